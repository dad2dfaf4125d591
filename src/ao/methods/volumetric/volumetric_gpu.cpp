// SPDX-License-Identifier: Apache-2.0
// Volumetric AO on the GPU (volumetric.comp): the CPU kernel's disk samples (make_disk_samples)
// and 4x4 rotations as uploaded tables, eq. 7's normaliser from the same points; then the 4x4
// depth-aware box filter (filters_gpu.cpp).
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/methods/volumetric/volumetric_gpu_internal.h"
#include "ao/methods/screen_space_gpu_internal.h"

namespace ao::gpu_detail {

MethodOutput run_gpu(Run& r, const GpuMethodInput& in, const VolumetricParams& params) {
  const Falloff& falloff = in.falloff;
  const std::uint32_t seed = in.seed;
  Falloff{Membership::Cubic, falloff.radius}.validate();
  check_gpu(params);
  const float radius = falloff.radius;
  const DiskSamples s = make_disk_samples(params.samples);
  std::vector<float> disk;
  // Eq. 7's normaliser from the same disk points: F = R sum h_i (summed in order, as the CPU) or 2Rn/3.
  float sum_h = 0;
  for (int i = 0; i < s.size(); ++i) {
    disk.insert(disk.end(), {s.x[i], s.y[i], s.h[i], 0.0f});
    sum_h += s.h[i];
  }
  const float F = params.normalizer == VolumeNormalizer::WeightedImportance ? radius * sum_h : 2.0f * radius * static_cast<float>(params.samples) / 3.0f;
  const Buffer points = make_buffer(r.c, std::span<const float>(disk));
  Texture raw = r.image(GL_R32F);
  Program& p = r.begin("volumetric.comp", "volumetric", sheets_define(params.layers));
  set_sampling(r, p, params.samples, params.bias, params.silhouette_elimination, radius, params.interleave, seed);
  r.set(p, "u_half_radius", 0.5f * radius);
  r.set(p, "u_inv_f", 1.0f / F);
  set_sheets(r, p, params.layers);
  r.bind(0, points);
  r.finish(raw);
  MethodOutput out;
  out.visibility = read_float(r.c, filtered(r, std::move(raw), 1, params.interleave, radius));
  return out;
}

}  // namespace ao::gpu_detail
