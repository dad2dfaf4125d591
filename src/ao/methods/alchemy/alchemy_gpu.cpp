// SPDX-License-Identifier: Apache-2.0
// Alchemy AO on the GPU (alchemy.comp), then the separable cross-bilateral filter
// (filters_gpu.cpp). The sample pattern is the CPU's:
// alchemy_internal.h's rotation table and golden-angle directions are uploaded, the per-pixel
// jitter and rotation index come from the same hash of the seed and the pixel.
#include <cmath>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/gpu/run_internal.h"
#include "ao/methods/alchemy/alchemy_gpu_internal.h"
#include "ao/methods/alchemy/alchemy_internal.h"
#include "ao/methods/filters/filters_gpu_internal.h"

namespace ao::gpu_detail {

MethodOutput run_gpu(Run& r, const GpuMethodInput& in, const AlchemyParams& params) {
  const Falloff& falloff = in.falloff;
  const std::uint32_t seed = in.seed;
  const AlchemyConstants k = alchemy_constants(params, falloff.radius);
  check_gpu(params);
  // The CPU method's own timings in --json, from the GPU passes that do their work.
  r.report_ms("estimator_ms", {"alchemy"});
  r.report_ms("filter_ms", {"filter"});
  const int s = params.samples;
  // The pattern's tables, as (cos, sin) pairs.
  const alchemy_internal::RotationTable& rot = alchemy_internal::rotations();
  std::vector<float> rotations, directions;
  for (int i = 0; i < alchemy_internal::kRotations; ++i) rotations.insert(rotations.end(), {rot.c[i], rot.s[i]});
  const alchemy_internal::Directions d = alchemy_internal::sample_directions(s);
  for (int i = 0; i < s; ++i) directions.insert(directions.end(), {d.x[i], d.y[i]});
  const Buffer rotation_buffer = make_buffer(r.c, std::span<const float>(rotations));
  const Buffer direction_buffer = make_buffer(r.c, std::span<const float>(directions));

  Texture raw = r.image(GL_R32F);
  Program& p = r.begin("alchemy.comp", "alchemy");
  r.set_rays(p);
  // Screen radius of the world disk: both image axes have 0.5 h / tan(fov/2) pixels per unit of
  // x/(-z), so the disk of radius r at depth z_C spans r * that / z_C pixels (sec. 2.3).
  const float px_per_unit = 0.5f * static_cast<float>(r.height()) / r.g.camera.tan_half_fov();
  r.set(p, "u_samples", s);
  r.set(p, "u_seed", seed);
  r.set(p, "u_radius_px", k.radius * px_per_unit);
  r.set(p, "u_r2", k.radius * k.radius);
  // 2 sigma / s: eq. 9's 2 pi u / s (uniform directions) times the paper's nominal 1/pi, u in sigma.
  r.set(p, "u_scale", 2.0f * k.sigma / static_cast<float>(s));
  r.set(p, "u_epsilon", k.epsilon);
  r.set(p, "u_beta", k.beta);
  r.set(p, "u_contrast", params.contrast);
  r.bind(0, rotation_buffer);
  r.bind(1, direction_buffer);
  r.finish(raw);

  MethodOutput out;
  if (params.filter && params.bilateral.taps > 1) {
    out.extras["unfiltered"] = read_float(r.c, raw);
    out.visibility = read_float(r.c, bilateral_filter(r, raw, params.bilateral, "filter"));
  } else {
    out.visibility = read_float(r.c, raw);
    if (params.filter) out.extras["unfiltered"] = out.visibility;
  }
  return out;
}

}  // namespace ao::gpu_detail
