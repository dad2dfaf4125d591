// SPDX-License-Identifier: Apache-2.0
// GTAO on the GPU (gtao.comp), its 4x4 denoiser (filters_gpu.cpp: box_filter.comp) and its
// multi-bounce fit (shaders/gtao_bounce.comp). The slice directions and step fractions are the CPU
// kernel's tables (gtao_internal.h), uploaded.
#include <cmath>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/gpu/run_internal.h"
#include "ao/methods/gtao/gtao_gpu_internal.h"
#include "ao/methods/filters/filters_gpu_internal.h"
#include "ao/methods/gtao/gtao_internal.h"

namespace ao::gpu_detail {

MethodOutput run_gpu(Run& r, const GpuMethodInput& in, const GtaoParams& params) {
  const Falloff& falloff = in.falloff;
  const std::uint32_t seed = in.seed;
  const float radius = falloff.radius;
  if (!(radius > 0.0f) || !std::isfinite(radius)) throw InputError("gtao: radius R must be a positive number of world units");
  if (params.multi_bounce && !r.g.has_albedo) throw InputError("gtao: multi_bounce reads the G-buffer's albedo, and it has none");
  const gtao_internal::Tables tables = gtao_internal::make_tables(params, seed);
  std::vector<float> directions, steps;
  for (int k = 0; k < params.slices; ++k)
    for (int p = 0; p < 16; ++p) directions.insert(directions.end(), {tables.dir_c[k][p], tables.dir_s[k][p]});
  for (int j = 0; j < params.steps; ++j) steps.insert(steps.end(), tables.step_t[j].begin(), tables.step_t[j].end());
  const Buffer direction_buffer = make_buffer(r.c, std::span<const float>(directions));
  const Buffer step_buffer = make_buffer(r.c, std::span<const float>(steps));

  Texture raw = r.image(GL_R32F);
  Program& p = r.begin("gtao.comp", "gtao");
  const Camera& cam = r.g.camera;
  const float t = cam.tan_half_fov();
  // Camera rays through pixel centres, and R's screen size per unit of x/(-z), as the CPU kernel.
  r.c.gl.Uniform4f(r.c.uniform(p, "u_rays"), 2.0f * t * cam.aspect() / static_cast<float>(r.width()), -t * cam.aspect(),
                   -2.0f * t / static_cast<float>(r.height()), t);
  r.set(p, "u_px_per_unit", 0.5f * static_cast<float>(r.height()) / t);
  r.set(p, "u_slices", params.slices);
  r.set(p, "u_steps", params.steps);
  r.set(p, "u_radius", radius);
  r.bind(0, direction_buffer);
  r.bind(1, step_buffer);
  r.finish(raw);
  const Texture v = params.interleave.interleave && params.interleave.filter
                        ? box_filter(r, raw, 1, effective_depth_limit(params.interleave, radius))
                        : std::move(raw);
  MethodOutput out;
  if (!params.multi_bounce) {
    out.visibility = read_float(r.c, v);
    return out;
  }
  const Texture bounce = r.map("gtao_bounce.comp", "multi_bounce", v, GL_RGBA32F);
  out.color = read_rgb(r.c, bounce);
  out.visibility = read_alpha(r.c, bounce);
  return out;
}

}  // namespace ao::gpu_detail
