// SPDX-License-Identifier: Apache-2.0
// What the screen-space methods' GPU runs share: screen_space_gpu_internal.h.
#include "ao/methods/screen_space_gpu_internal.h"

#include <string>
#include <vector>

#include "ao/core/error.h"
#include "ao/methods/filters/filters_gpu_internal.h"
#include "ao/methods/samples.h"
#include "ao/methods/screen_space_kernel_internal.h"

namespace ao::gpu_detail {

void set_sampling(Run& r, Program& p, int samples, float bias, bool silhouette_elimination, float radius, const InterleaveOptions& interleave,
                  std::uint32_t seed) {
  set_rotations(r, p, interleave_rotations(seed, interleave.interleave));
  r.set(p, "u_samples", samples);
  r.set(p, "u_bias", bias);
  r.set(p, "u_far_limit", silhouette_elimination ? -radius : -kInfinity);
  // One pixel's footprint at unit depth: the image plane spans 2 tan(fov/2) over `height` pixels.
  r.set(p, "u_footprint", 2.0f * r.g.camera.tan_half_fov() / static_cast<float>(r.height()));
}

std::string_view sheets_define(const DepthLayers& layers) { return layers.thickness > 0 ? "#define AO_SHEETS 1\n" : ""; }

void set_sheets(Run& r, Program& p, const DepthLayers& layers) {
  if (layers.thickness <= 0) return;
  r.set(p, "u_thickness", layers.thickness);
  r.set(p, "u_crossing_tolerance", simd::kCrossingTolerance * layers.thickness);
}

// The containment-test offsets (X, Y, Z, r) of make_containment_samples, as vec4s.
Buffer containment_offsets(Run& r, int n, const Falloff& falloff) {
  const ContainmentSamples s = make_containment_samples(n, falloff);
  std::vector<float> v;
  for (int i = 0; i < s.size(); ++i) v.insert(v.end(), {s.x[i], s.y[i], s.z[i], s.r[i]});
  return make_buffer(r.c, std::span<const float>(v));
}

// The filter after an interleaved pass, when the options ask for it.
Texture filtered(Run& r, Texture raw, int channels, const InterleaveOptions& o, float radius) {
  if (!(o.interleave && o.filter)) return raw;
  return box_filter(r, raw, channels, effective_depth_limit(o, radius));
}

}  // namespace ao::gpu_detail
