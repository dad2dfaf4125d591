// SPDX-License-Identifier: Apache-2.0
// What the screen-space methods' shaders share (containment.comp, volumetric.comp, transfer.comp),
// after common.glsl: their automatic depth-test bias and one layer's sheets, with the constants the
// CPU kernels read.
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

// One layer's sheets (methods/depth_layers.h, `thickness`): u_thickness > 0 takes every visible
// surface for a sheet that thick with nothing behind it, as the CPU kernels read a second layer that
// holds nothing (screen_space_vec_internal.h Plane::in_solid, sheet_hides); 0: everything behind the
// depth buffer is solid (VAO fig. 2c). Compiled with AO_SHEETS only (screen_space_gpu.cpp
// sheets_define); u_crossing_tolerance: kCrossingTolerance x u_thickness.
#ifdef AO_SHEETS
uniform float u_thickness;
uniform float u_crossing_tolerance;

// Whether the sheet seen at pixel `at` hides point q behind it from receiver r (`on_sheet`: the
// sheet's point in front of q where q is read along): r lies on the camera's side of the sheet's
// tangent plane there (the pixel's normal) within `tol`, and the segment r -> q meets that plane
// where the sheet is seen: at the meeting point's pixel the visible surface is no more than
// u_crossing_tolerance behind it (past the sheet's rim it lies further back).
bool sheet_hides(ivec2 at, vec3 on_sheet, vec3 r, vec3 q, float tol) {
  const vec3 nq = texelFetch(u_normal, at, 0).xyz;
  const float w = dot(nq, on_sheet);
  const float side_r = dot(nq, r) - w;
  if (side_r < -tol) return false;
  // q on r's side of the plane too (a curved sheet seen at a grazing angle): no meeting point, and
  // t = 1 puts it at q, which keeps one layer's answer (hidden).
  const float den = side_r - (dot(nq, q) - w);
  const float t = den > 0.0 ? min(max(side_r, 0.0) / den, 1.0) : 1.0;
  const vec3 c = r + t * (q - r);
  bool valid;
  return !(depth_at(locate(c, valid)) > u_crossing_tolerance - c.z);
}

// Whether point q, behind the first layer z1 of its pixel `at`, lies in the solid for receiver r:
// within the sheet's thickness, or beyond it where the sheet hides it (q's line of sight meets the
// sheet at q z1 / z).
bool in_sheets_solid(float z1, ivec2 at, vec3 r, vec3 q, float tol) {
  const float z = -q.z;
  return z < z1 + u_thickness || sheet_hides(at, q * (z1 / z), r, q, tol);
}
#endif
