#version 430
// SPDX-License-Identifier: Apache-2.0
// Containment-test ambient occlusion, one invocation per pixel. Based on Szirmay-Kalos, Umenhoffer,
// Toth, Szecsi, Sbert, "Volumetric Ambient Occlusion for Real-Time Rendering and Games" (VAO),
// eq. 4-5, with the samples of Umenhoffer, Toth, Szirmay-Kalos, "Efficient Methods for Ambient
// Lighting" (AT), sec. 4-4.3 (the CPU kernel: src/ao/methods/containment/containment.cpp):
//
//   O(x) ~ (1/n) sum_i I(x + X_i T + Y_i B + Z_i N)                              (VAO eq. 5)
//
// (X_i, Y_i, Z_i) = w_i r_i: w_i cosine distributed, r_i = mu^-1(xi_i) (AT eq. 8), so O estimates
// the obscurance (VAO eq. 2) of the membership mu. The paper's O is openness: V = O, written to
// o_visibility (1 where not covered). With m > 1 steps a ray is free only when all of its m tests
// at r_i j/m are (AT sec. 4). I(p) is the depth buffer (VAO fig. 2c): p is occluded when the
// surface stored at its pixel is in front of it by more than the bias and, with silhouette
// elimination (AT 4.3), by less than R. The pixel's tangent frame (T, B) is turned by its 4x4
// interleaving angle about N (VAO and AT sec. 4.2); box_filter.comp then averages the 4x4 blocks.
//
// Uniforms (set from ContainmentParams and the Falloff; containment_gpu.cpp):
//   u_size, u_projection   common.glsl
//   u_samples       n, [1, 256]
//   u_ray_steps     m, [1, 8]
//   u_far_limit     -R with silhouette elimination, -infinity without (a test is occluded when
//                   -bias > distance > u_far_limit)
//   u_bias          depth-test bias, world units; 0 = automatic (screen_space.glsl depth_bias)
//   u_footprint     one pixel's footprint at unit depth, 2 tan(fov/2) / height
//   u_rotation[16]  (cos, sin) of the 4x4 pattern's angles, entry (y % 4) * 4 + x % 4 (samples.h)
//   u_thickness     with AO_SHEETS, one layer's sheets (screen_space.glsl)
// Buffers: binding 0, the sample offsets (X_i, Y_i, Z_i, r_i) of make_containment_samples, world units.
#include "common.glsl"
#include "screen_space.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, r32f) uniform writeonly image2D o_visibility;
layout(std430, binding = 0) readonly buffer Samples { vec4 u_offsets[]; };

uniform int u_samples;
uniform int u_ray_steps;
uniform float u_far_limit;
uniform float u_bias;
uniform float u_footprint;
uniform vec2 u_rotation[16];

// Whether camera-space point q is occluded for receiver r (bias: r's depth-test bias): behind the
// surface at its pixel by more than the bias (the depth buffer's distance z* - depth(q),
// characteristic.h, +infinity behind the camera) and, with silhouette elimination, by less than R;
// with one layer's sheets also inside their solid.
bool occluded(vec3 r, vec3 q, float bias) {
  bool valid;
  const ivec2 at = locate(q, valid);
  const float z1 = depth_at(at);
  const float d = valid ? z1 + q.z : kInfinity;
#ifdef AO_SHEETS
  return d < -bias && d > u_far_limit && in_sheets_solid(z1, at, r, q, bias);
#else
  return d < -bias && d > u_far_limit;
#endif
}

void main() {
  const ivec2 pix = ivec2(gl_GlobalInvocationID.xy);
  if (pix.x >= u_size.x || pix.y >= u_size.y) return;
  if (!covered(pix)) {
    imageStore(o_visibility, pix, vec4(1.0));
    return;
  }
  const vec3 p = texelFetch(u_position, pix, 0).xyz, n = texelFetch(u_normal, pix, 0).xyz;
  const vec2 rot = u_rotation[(pix.y & 3) * 4 + (pix.x & 3)];
  const float bias = depth_bias(p, n, u_bias, u_footprint);
  // Sec. 4.2: T' = cos a T + sin a B, B' = -sin a T + cos a B.
  vec3 t0, b0;
  frame_from_normal(n, t0, b0);
  const vec3 t = t0 * rot.x + b0 * rot.y, b = b0 * rot.x - t0 * rot.y;
  const float inv_m = 1.0 / float(u_ray_steps);
  float open = 0.0;
  for (int i = 0; i < u_samples; ++i) {
    const vec3 s = u_offsets[i].xyz;
    bool blocked = false;
    for (int j = 1; j <= u_ray_steps; ++j) {
      // VAO eq. 5's point (AT sec. 4: at r_i j / m along the ray; j = m is eq. 5's own).
      const float f = u_ray_steps == 1 ? 1.0 : float(j) * inv_m;
      const vec3 q = p + (f * s.x) * t + (f * s.y) * b + (f * s.z) * n;
      blocked = blocked || occluded(p, q, bias);
    }
    open += blocked ? 0.0 : 1.0;
  }
  imageStore(o_visibility, pix, vec4(open * (1.0 / float(u_samples))));  // eq. 5: the mean of I
}
