#version 430
// SPDX-License-Identifier: Apache-2.0
// The depth-aware 4x4 box filter after an interleaved pass, one invocation per pixel (VAO and AT
// sec. 4.2, interleaved sampling after Keller and Heidrich 2001; the CPU filter:
// src/ao/methods/filters/interleave.cpp). Neighbours at offsets -2..+1 in x and y hold each of the 16
// pattern entries once; those not covered, or whose depth differs from the centre's by more than
// u_depth_limit, are skipped; the rest are averaged, summed row by row in the order of the CPU
// filter. Uncovered pixels keep their value. Used by containment, volumetric, transfer (W and O in
// one RGBA image: CHANNELS 4) and GTAO.
//
// Defines: CHANNELS 1 (r32f images) or 4 (rgba32f). Uniforms: u_size (common.glsl); u_depth_limit,
// world units (InterleaveOptions::filter_depth_limit, 0 there meaning R/4).
#include "common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 6) uniform sampler2D u_values;
#if CHANNELS == 4
layout(binding = 0, rgba32f) uniform writeonly image2D o_filtered;
#else
layout(binding = 0, r32f) uniform writeonly image2D o_filtered;
#endif

uniform float u_depth_limit;

void main() {
  const ivec2 pix = ivec2(gl_GlobalInvocationID.xy);
  if (pix.x >= u_size.x || pix.y >= u_size.y) return;
  const vec4 centre = texelFetch(u_values, pix, 0);
  if (!covered(pix)) {
    imageStore(o_filtered, pix, centre);
    return;
  }
  const float dc = depth_at(pix);
  float count = 0.0;
  vec4 sum = vec4(0.0);
  for (int dy = max(-2, -pix.y); dy <= min(1, u_size.y - 1 - pix.y); ++dy)
    for (int dx = max(-2, -pix.x); dx <= min(1, u_size.x - 1 - pix.x); ++dx) {
      const ivec2 q = pix + ivec2(dx, dy);
      // Background has depth +infinity: never within the limit.
      const bool use = abs(depth_at(q) - dc) <= u_depth_limit;
      count += use ? 1.0 : 0.0;
      sum += use ? texelFetch(u_values, q, 0) : vec4(0.0);
    }
  imageStore(o_filtered, pix, count > 0.0 ? sum / count : centre);
}
