#version 430
// SPDX-License-Identifier: Apache-2.0
// GTAO's multi-bounce approximation (Jimenez et al. 2016, "Multi-bounce approximation": a cubic
// fitted to path-traced references), per pixel on the filtered visibility V with the G-buffer's
// albedo rho (gtao_shared.h: multi_bounce_fit, which the CPU's gtao_multi_bounce calls too):
//
//   V'(V, rho) = max(V, ((a V + b) V + c) V), a = 2.0404 rho - 0.3324,
//                b = -4.7951 rho + 0.6417, c = 2.7552 rho + 0.6903
//
// Output o_bounce: (V'(V, rho_r), V'(V, rho_g), V'(V, rho_b), V'(V, luminance of rho)) on covered
// pixels (Rec. 709 luminance), (1, 1, 1, 1) elsewhere. Uniforms: u_size (common.glsl).
#include "common.glsl"
#include "ao/core/color_shared.h"
#include "gtao_shared.h"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 6) uniform sampler2D u_values;
layout(binding = 0, rgba32f) uniform writeonly image2D o_bounce;

void main() {
  const ivec2 pix = ivec2(gl_GlobalInvocationID.xy);
  if (pix.x >= u_size.x || pix.y >= u_size.y) return;
  if (!covered(pix)) {
    imageStore(o_bounce, pix, vec4(1.0));
    return;
  }
  const float v = texelFetch(u_values, pix, 0).r;
  const vec3 rho = texelFetch(u_albedo, pix, 0).rgb;
  const float rho_y = luminance(rho.r, rho.g, rho.b);
  imageStore(o_bounce, pix, vec4(multi_bounce_fit(v, rho.r), multi_bounce_fit(v, rho.g), multi_bounce_fit(v, rho.b), multi_bounce_fit(v, rho_y)));
}
