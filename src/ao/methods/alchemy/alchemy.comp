#version 430
// SPDX-License-Identifier: Apache-2.0
// Alchemy screen-space ambient obscurance, one invocation per pixel. Based on McGuire, Osman,
// Bukowski, Hennessy, "The Alchemy Screen-Space Ambient Obscurance Algorithm" (HPG 2011), eq. 10
// (the CPU kernel: src/ao/methods/alchemy/alchemy.cpp):
//
//   A = max(0, 1 - (2 sigma / s) * sum_i max(0, v_i . n + z_C beta) H(r - |v_i|) / (v_i . v_i + epsilon))^k
//
// v_i = P_i - C, with P_i read at the samples of sec. 2.3: uniform on the screen-space projection
// of the disk of radius r about C parallel to the image plane. Sample i lies in the i-th of s
// equal-area annuli (radius sqrt((i + jitter) / s) of the disk's screen radius) at angle i times
// the golden angle plus the pixel's rotation; jitter and rotation come from pixel_seed(seed, x, y),
// so the pattern is the CPU's, sample for sample. H is eq. 9's cut at r. Positions are
// reconstructed from the depth buffer, P = z(Q') (camera ray through Q's pixel centre), for C too,
// so C and its samples agree exactly on a plane. The paper's A is accessibility: V = A. Samples
// beyond the image read its border pixel (clamp-to-edge); background samples (depth +infinity)
// contribute nothing. Output: V before the cross-bilateral filter (bilateral.comp).
//
// Uniforms (AlchemyConstants and AlchemyParams; src/ao/methods/alchemy/alchemy_gpu.cpp):
//   u_size          common.glsl
//   u_samples       s, [1, 1024]
//   u_seed          the run's seed
//   u_radius_px     r * pixels per unit of x/(-z) (its screen radius at unit depth)
//   u_r2            r^2, world units^2
//   u_scale         2 sigma / s (sigma in world units)
//   u_epsilon       epsilon, world units^2
//   u_beta          beta (dimensionless)
//   u_contrast      k
//   u_rays          (ax, bx, ay, by): camera_direction(px, py) = (ax px + bx, ay py + by, -1)
// Buffers: binding 0 the 1024 rotations (cos, sin); binding 1 the sample directions (cos, sin of
// i times the golden angle); both alchemy_internal.h's tables.
#include "common.glsl"
#include "alchemy_shared.h"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, r32f) uniform writeonly image2D o_visibility;
layout(std430, binding = 0) readonly buffer Rotations { vec2 u_rotations[]; };
layout(std430, binding = 1) readonly buffer Directions { vec2 u_directions[]; };

uniform int u_samples;
uniform uint u_seed;
uniform float u_radius_px;
uniform float u_r2;
uniform float u_scale;
uniform float u_epsilon;
uniform float u_beta;
uniform float u_contrast;
uniform vec4 u_rays;


// sqrt(x) for x in [0, 1] as the CPU kernel computes it: the reciprocal square root bit trick and
// two Newton steps (relative error < 5e-6), so both backends place the samples alike.
float sqrt_unit(float x) {
  float r = uintBitsToFloat(kInvSqrtMagic - (floatBitsToUint(x) >> 1));
  r = r * (1.5 - 0.5 * x * r * r);
  r = r * (1.5 - 0.5 * x * r * r);
  return x * r;
}

vec3 position_at(ivec2 q, float depth) {
  return vec3(depth * (u_rays.x * (float(q.x) + 0.5) + u_rays.y), depth * (u_rays.z * (float(q.y) + 0.5) + u_rays.w), -depth);
}

void main() {
  const ivec2 pix = ivec2(gl_GlobalInvocationID.xy);
  if (pix.x >= u_size.x || pix.y >= u_size.y) return;
  if (!covered(pix)) {
    imageStore(o_visibility, pix, vec4(1.0));
    return;
  }
  const float d = depth_at(pix);
  const vec3 c = position_at(pix, d), n = texelFetch(u_normal, pix, 0).xyz;
  // Eq. 10's z_C beta: z_C < 0, so this lowers v.n and drops samples nearly in the tangent plane.
  const float bias = c.z * u_beta;
  const float radius_px = min(kAlchemyMaxPixelRadius, u_radius_px / d);
  const uint hs = pixel_seed(u_seed, pix.x, pix.y);
  const float jitter = to_unit_float(hs);
  const vec2 rot = u_rotations[hash32(hs) & 1023u];
  const float fx0 = float(pix.x) + 0.5 + kAlchemyCoordOffset, fy0 = float(pix.y) + 0.5 + kAlchemyCoordOffset;
  const float inv_s = 1.0 / float(u_samples);
  float sum = 0.0;
  for (int i = 0; i < u_samples; ++i) {
    const vec2 u = u_directions[i];
    const float rho = radius_px * sqrt_unit((float(i) + jitter) * inv_s);
    const float dx = rho * (rot.x * u.x - rot.y * u.y), dy = rho * (rot.y * u.x + rot.x * u.y);
    const ivec2 q = clamp(ivec2(int(fx0 + dx), int(fy0 + dy)) - ivec2(int(kAlchemyCoordOffset)), ivec2(0), u_size - 1);
    const vec3 v = position_at(q, depth_at(q)) - c;
    const float vv = v.x * v.x + v.y * v.y + v.z * v.z;
    const float vn = v.x * n.x + v.y * n.y + v.z * n.z + bias;
    // H of eq. 9 and the max(0, .) of eq. 10; background samples (vv infinite or NaN) fail vv < r^2.
    if (vv < u_r2 && vn > 0.0) sum += vn / (vv + u_epsilon);
  }
  float a = max(0.0, 1.0 - u_scale * sum);  // eq. 10 before ^k
  if (u_contrast != 1.0) a = pow(a, u_contrast);
  imageStore(o_visibility, pix, vec4(a));
}
