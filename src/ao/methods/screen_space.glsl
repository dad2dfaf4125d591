// SPDX-License-Identifier: Apache-2.0
// What the screen-space methods' shaders share (containment.comp, volumetric.comp, transfer.comp),
// after common.glsl: their automatic depth-test bias, with the constants the CPU kernels read.
#include "ao/methods/screen_space_shared.h"

// The automatic depth-test bias (screen_space_kernel.cpp set_bias): one pixel's footprint at the
// point's depth times (1 + tan theta_v), theta_v the angle between the normal and the view ray,
// clamped at tan = 8 (cos theta_v >= kMinViewCosine): the most a nearest-pixel depth lookup on the
// same surface can be off by. `bias_world` > 0 replaces it.
float depth_bias(vec3 p, vec3 n, float bias_world, float footprint) {
  if (bias_world > 0.0) return bias_world;
  const float len = sqrt(dot(p, p));
  const vec3 u = len > 0.0 ? p / len : p;
  const float cos_v = max(abs(dot(n, u)), kMinViewCosine);
  const float tan_v = sqrt(1.0 - cos_v * cos_v) / cos_v;
  return footprint * (-p.z) * (1.0 + tan_v);
}
