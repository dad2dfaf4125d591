#version 430
// SPDX-License-Identifier: Apache-2.0
// One 1-D pass of the separable cross-bilateral filter, one invocation per pixel. Based on McGuire,
// Osman, Bukowski, Hennessy, "The Alchemy Screen-Space Ambient Obscurance Algorithm" (HPG 2011),
// sec. 2 (Listing 1, pass 5) and Figure 6: "two 13-tap 1D cross-bilateral filter passes" over the
// obscurance buffer, weighted by camera-space proximity to the surface being shaded (the CPU
// filter: src/ao/methods/filters/bilateral.cpp). The paper gives no weight; ours (docs/methods/alchemy.md):
//
//   w(j) = G(j; spatial_sigma) * K(|n_C . (P_j - C)| / plane_sigma(C)),  K(x) = max(0, 1 - x^2 / 4)^2
//
// C, n_C the centre pixel's position and normal, P_j the tap's, positions rebuilt as depth times
// the camera ray through the pixel centre. With C = d0 (rx, ry, -1) and a tap at depth d on the ray
// (tx, ty, -1), x/2 = |d (a t + b) - c| with s = 1 / (plane_sigma d0) and t the ray coordinate
// that varies along the pass:
//   horizontal: a = nx s/2, b = (ny ry - nz) s/2;  vertical: a = ny s/2, b = (nx rx - nz) s/2;  c = (n . C) s/2.
// Background taps (depth +infinity) and taps beyond the image weigh 0; background pixels keep their
// value. Both passes sum the taps in order, as the CPU filter, so the result is the CPU's up to rounding.
//
// Uniforms (BilateralParams; src/ao/methods/alchemy/alchemy_gpu.cpp): u_size (common.glsl); u_vertical (0: the
// horizontal pass, 1: the vertical one); u_taps (odd, [1, 63]); u_spatial[63] (G(j - taps/2), the
// CPU's exp(-0.5 j^2 / sigma^2)); u_plane_sigma; u_rays (ax, bx, ay, by) as alchemy.comp.
#include "common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 6) uniform sampler2D u_values;
layout(binding = 0, r32f) uniform writeonly image2D o_filtered;

uniform int u_vertical;
uniform int u_taps;
uniform float u_spatial[63];
uniform float u_plane_sigma;
uniform vec4 u_rays;

void main() {
  const ivec2 pix = ivec2(gl_GlobalInvocationID.xy);
  if (pix.x >= u_size.x || pix.y >= u_size.y) return;
  const float value = texelFetch(u_values, pix, 0).r;
  if (!covered(pix)) {
    imageStore(o_filtered, pix, vec4(value));
    return;
  }
  const vec3 n = texelFetch(u_normal, pix, 0).xyz;
  const float d = depth_at(pix);
  const float rx = u_rays.x * (float(pix.x) + 0.5) + u_rays.y, ry = u_rays.z * (float(pix.y) + 0.5) + u_rays.w;
  const float half_s = 0.5 / (u_plane_sigma * d);
  const float a = (u_vertical != 0 ? n.y : n.x) * half_s;
  const float b = (u_vertical != 0 ? n.x * rx - n.z : n.y * ry - n.z) * half_s;
  const float c = d * (n.x * rx + n.y * ry - n.z) * half_s;
  const int half_taps = u_taps / 2;
  float sum_w = 0.0, sum_v = 0.0;
  for (int j = 0; j < u_taps; ++j) {
    const int offset = j - half_taps;
    const ivec2 q = pix + (u_vertical != 0 ? ivec2(0, offset) : ivec2(offset, 0));
    if (q.x < 0 || q.y < 0 || q.x >= u_size.x || q.y >= u_size.y) continue;  // beyond the image: weight 0
    const float t = u_vertical != 0 ? u_rays.z * (float(q.y) + 0.5) + u_rays.w : u_rays.x * (float(q.x) + 0.5) + u_rays.y;
    const float dq = depth_at(q);
    const float half_x = dq * (a * t + b) - c;
    // K = max(0, 1 - (x/2)^2)^2; background taps (d = +infinity: x infinite or NaN) weigh 0.
    const float u = max(0.0, 1.0 - half_x * half_x);
    const float w = dq < kInfinity ? u_spatial[j] * (u * u) : 0.0;
    sum_w += w;
    sum_v += w * texelFetch(u_values, q, 0).r;
  }
  // The centre tap weighs spatial(0) * 1 > 0 on covered pixels, so sum_w > 0.
  imageStore(o_filtered, pix, vec4(sum_v / sum_w));
}
