#version 430
// GTAO's multi-bounce approximation (Jimenez et al. 2016, "Multi-bounce approximation": a cubic
// fitted to path-traced references), per pixel on the filtered visibility V with the G-buffer's
// albedo rho (the CPU: gtao_multi_bounce in src/ao/methods/gtao/gtao.cpp):
//
//   V'(V, rho) = max(V, ((a V + b) V + c) V), a = 2.0404 rho - 0.3324,
//                b = -4.7951 rho + 0.6417, c = 2.7552 rho + 0.6903
//
// Output o_bounce: (V'(V, rho_r), V'(V, rho_g), V'(V, rho_b), V'(V, luminance of rho)) on covered
// pixels (Rec. 709 luminance), (1, 1, 1, 1) elsewhere. Uniforms: u_size (common.glsl).
#include "common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 6) uniform sampler2D u_values;
layout(binding = 0, rgba32f) uniform writeonly image2D o_bounce;

float multi_bounce(float v, float rho) {
  const float a = 2.0404 * rho - 0.3324, b = -4.7951 * rho + 0.6417, c = 2.7552 * rho + 0.6903;
  return max(v, ((a * v + b) * v + c) * v);
}

void main() {
  const ivec2 pix = ivec2(gl_GlobalInvocationID.xy);
  if (pix.x >= u_size.x || pix.y >= u_size.y) return;
  if (!covered(pix)) {
    imageStore(o_bounce, pix, vec4(1.0));
    return;
  }
  const float v = texelFetch(u_values, pix, 0).r;
  const vec3 rho = texelFetch(u_albedo, pix, 0).rgb;
  const float luminance = 0.2126 * rho.r + 0.7152 * rho.g + 0.0722 * rho.b;
  imageStore(o_bounce, pix, vec4(multi_bounce(v, rho.r), multi_bounce(v, rho.g), multi_bounce(v, rho.b), multi_bounce(v, luminance)));
}
