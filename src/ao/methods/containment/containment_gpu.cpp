// SPDX-License-Identifier: Apache-2.0
// Containment AO on the GPU (containment.comp): the CPU kernel's test offsets
// (make_containment_samples) and 4x4 rotations (interleave_rotations) as uploaded tables, so both
// backends sample the same points; then the 4x4 depth-aware box filter (filters_gpu.cpp).
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/methods/containment/containment_gpu_internal.h"
#include "ao/methods/screen_space_gpu_internal.h"

namespace ao::gpu_detail {

MethodOutput run_gpu(Run& r, const GpuMethodInput& in, const ContainmentParams& params) {
  const Falloff& falloff = in.falloff;
  const std::uint32_t seed = in.seed;
  falloff.validate();
  check_gpu(params);
  const Buffer offsets = containment_offsets(r, params.samples, falloff);
  Texture raw = r.image(GL_R32F);
  Program& p = r.begin("containment.comp", "containment", sheets_define(params.layers));
  set_sampling(r, p, params.samples, params.bias, params.silhouette_elimination, falloff.radius, params.interleave, seed);
  r.set(p, "u_ray_steps", params.ray_steps);
  set_sheets(r, p, params.layers);
  r.bind(0, offsets);
  r.finish(raw);
  MethodOutput out;
  out.visibility = read_float(r.c, filtered(r, std::move(raw), 1, params.interleave, falloff.radius));
  return out;
}

}  // namespace ao::gpu_detail
