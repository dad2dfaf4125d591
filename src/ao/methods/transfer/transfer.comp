#version 430
// SPDX-License-Identifier: Apache-2.0
// Ambient transfer, one invocation per pixel. Based on Umenhoffer, Toth, Szirmay-Kalos, "Efficient
// Methods for Ambient Lighting" (AT), eq. 6, 7 and 9 (the CPU kernel: src/ao/methods/transfer/transfer.cpp):
//
//   W(x) ~ sum_i I(p_i) / (n - sum_i (1 - I(p_i)) a~(p_i))        per RGB channel   (eq. 9)
//
// with the containment-test samples p_i = x + X_i T + Y_i B + Z_i N of eq. 8 (cosine directions,
// r_i = mu^-1(xi)), I(p_i) the product of m tests at r_i j/m along the ray (sec. 4), and a~ the
// albedo read at the pixel of the NEAREST test point found occluded (sec. 4; the tests run from the
// far end inwards, each occluded one overwriting the pixel). W is obscurance plus the light of
// further bounces under W(y) ~ W(x) (eq. 6); the obscurance O = (1/n) sum I (eq. 5) comes from the
// same tests. Where no ray is open W = 0 (eq. 9 would be 0 / 0 with white occluders).
//
// Radiance mode (u_radiance = 1; AT 4.1's remark after eq. 9; derivation in
// docs/methods/transfer.md): the occluders' direct radiance Ld~ (G-buffer direct pass, in units
// of the ambient) joins the numerator, W = (sum I + s sum (1 - I) Ld~) / (n - s sum (1 - I) a~),
// not clamped, 0 unless numerator and denominator are > 0.
//
// Output o_transfer: (W_r, W_g, W_b, O), 1 where not covered; box_filter.comp filters all four,
// transfer_finish.comp takes the Rec. 709 luminance of W as the visibility.
//
// Uniforms (TransferParams and the Falloff; transfer_gpu.cpp):
//   u_size, u_projection  common.glsl
//   u_samples, u_ray_steps  n in [1, 256], m in [1, 8]
//   u_far_limit    -R with silhouette elimination (AT 4.3), -infinity without
//   u_bias, u_footprint  the depth-test bias (0 = automatic) and one pixel's footprint at unit depth
//   u_albedo_scale s, multiplies a~ and Ld~, [0, 1]
//   u_radiance     0: eq. 9 (albedo); 1: the radiance mode
//   u_rotation[16] the 4x4 pattern's (cos, sin) about N
//   u_thickness    with AO_SHEETS, one layer's sheets (screen_space.glsl)
// Buffers: binding 0, the sample offsets (X_i, Y_i, Z_i, r_i), world units.
#include "common.glsl"
#include "screen_space.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba32f) uniform writeonly image2D o_transfer;
layout(std430, binding = 0) readonly buffer Samples { vec4 u_offsets[]; };

uniform int u_samples;
uniform int u_ray_steps;
uniform float u_far_limit;
uniform float u_bias;
uniform float u_footprint;
uniform float u_albedo_scale;
uniform int u_radiance;
uniform vec2 u_rotation[16];

void main() {
  const ivec2 pix = ivec2(gl_GlobalInvocationID.xy);
  if (pix.x >= u_size.x || pix.y >= u_size.y) return;
  if (!covered(pix)) {
    imageStore(o_transfer, pix, vec4(1.0));
    return;
  }
  const vec3 p = texelFetch(u_position, pix, 0).xyz, n = texelFetch(u_normal, pix, 0).xyz;
  const vec2 rot = u_rotation[(pix.y & 3) * 4 + (pix.x & 3)];
  const float bias = depth_bias(p, n, u_bias, u_footprint);
  vec3 t0, b0;
  frame_from_normal(n, t0, b0);
  const vec3 t = t0 * rot.x + b0 * rot.y, b = b0 * rot.x - t0 * rot.y;  // sec. 4.2
  const float inv_m = 1.0 / float(u_ray_steps);
  float open = 0.0;
  vec3 lost = vec3(0.0), gain = vec3(0.0);
  for (int i = 0; i < u_samples; ++i) {
    const vec3 s = u_offsets[i].xyz;
    // Sec. 4: the nearest occluded test point names a~'s pixel; -1: the ray is free.
    ivec2 at = ivec2(-1);
    for (int j = u_ray_steps; j >= 1; --j) {
      const float f = float(j) * inv_m;
      const vec3 q = p + (f * s.x) * t + (f * s.y) * b + (f * s.z) * n;  // eq. 8, step j of m
      bool valid;
      const ivec2 q_pixel = locate(q, valid);
      const float z1 = depth_at(q_pixel);
      const float d = valid ? z1 + q.z : kInfinity;
      // AT 4.3: only a surface less than R in front occludes; with one layer's sheets, inside their solid.
#ifdef AO_SHEETS
      if (d < -bias && d > u_far_limit && in_sheets_solid(z1, q_pixel, p, q, bias)) at = q_pixel;
#else
      if (d < -bias && d > u_far_limit) at = q_pixel;
#endif
    }
    if (at.x < 0) {
      open += 1.0;
    } else {
      lost += texelFetch(u_albedo, at, 0).rgb;           // (1 - I) a~ of eq. 9's denominator
      if (u_radiance != 0) gain += texelFetch(u_direct, at, 0).rgb;  // (1 - I) Ld~ of the radiance mode
    }
  }
  const float nf = float(u_samples), s = u_albedo_scale;
  vec3 w;
  if (u_radiance != 0) {
    const vec3 num = open + s * gain, den = nf - s * lost;
    for (int k = 0; k < 3; ++k) w[k] = num[k] > 0.0 && den[k] > 0.0 ? num[k] / den[k] : 0.0;
  } else {
    // Eq. 9; the denominator is >= sum I since a~ <= 1.
    w = open > 0.0 ? min(open / (nf - s * lost), vec3(1.0)) : vec3(0.0);
  }
  imageStore(o_transfer, pix, vec4(w, open / nf));  // O: eq. 5 from the same tests
}
