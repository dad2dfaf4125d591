// SPDX-License-Identifier: Apache-2.0
// Ambient transfer on the GPU (transfer.comp, then transfer_finish.comp for W's luminance): the
// CPU kernel's test offsets and 4x4 rotations as uploaded tables; sec. 4.2's box filter on W and O
// alike (filters_gpu.cpp).
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/methods/transfer/transfer_gpu_internal.h"
#include "ao/methods/screen_space_gpu_internal.h"

namespace ao::gpu_detail {

MethodOutput run_gpu(Run& r, const GpuMethodInput& in, const TransferParams& params) {
  const Falloff& falloff = in.falloff;
  const std::uint32_t seed = in.seed;
  falloff.validate();
  check_gpu(params);
  if (!r.g.has_albedo) throw InputError("transfer: the indirect reflectance image must have the G-buffer's size (the G-buffer has no albedo)");
  const bool radiance = params.reflectance == TransferReflectance::Radiance;
  if (radiance && !r.g.direct)
    throw InputError("transfer: reflectance=radiance reads the occluders' direct light, and the G-buffer has no direct-light pass");
  const Buffer offsets = containment_offsets(r, params.samples, falloff);
  Texture raw = r.image(GL_RGBA32F);
  Program& p = r.begin("transfer.comp", "transfer", sheets_define(params.layers));
  set_sampling(r, p, params.samples, params.bias, params.silhouette_elimination, falloff.radius, params.interleave, seed);
  r.set(p, "u_ray_steps", params.ray_steps);
  r.set(p, "u_albedo_scale", params.albedo_scale);
  r.set(p, "u_radiance", radiance ? 1 : 0);
  set_sheets(r, p, params.layers);
  r.bind(0, offsets);
  r.finish(raw);
  // Sec. 4.2's filter on W and O alike, then the luminance of W.
  const Texture wo = filtered(r, std::move(raw), 4, params.interleave, falloff.radius);
  MethodOutput out;
  out.visibility = read_float(r.c, r.map("transfer_finish.comp", "luminance", wo, GL_R32F));
  out.color = read_rgb(r.c, wo);
  out.extras["obscurance"] = read_alpha(r.c, wo);
  return out;
}

}  // namespace ao::gpu_detail
