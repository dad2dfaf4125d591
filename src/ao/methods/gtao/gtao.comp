#version 430
// SPDX-License-Identifier: Apache-2.0
// Ground-truth-based ambient occlusion (GTAO), one invocation per pixel. Based on Jimenez, Wu,
// Pesce, Jarabo, "Practical Realtime Strategies for Accurate Indirect Occlusion" (Activision tech.
// memo ATVI-TR-16-01, SIGGRAPH 2016 course); the CPU kernel, with the same steps and tables:
// src/ao/methods/gtao.cpp.
//
//   A(x) = (1/pi) int_H V(w) (n . w)+ dw                                                 (eq. 1)
//   horizon form, slices through the view vector w_o at screen angles phi:
//   A(x) = (1/pi) int_0^pi |n_p(phi)| a(phi) dphi
//   analytic inner integral ("GTAO: the inner integral"):
//   a(phi) = 1/4 (-cos(2 h1 - gamma) + cos gamma + 2 h1 sin gamma)
//          + 1/4 (-cos(2 h2 - gamma) + cos gamma + 2 h2 sin gamma)
//   with the horizons clamped to the hemisphere of the projected normal:
//   h1 = gamma + max(-theta1 - gamma, -pi/2), h2 = gamma + min(theta2 - gamma, pi/2)
//
// theta is the angle in the slice plane from w_o, theta1 and theta2 the horizons found by marching
// the depth buffer on both sides, n_p the normal projected onto the slice plane, gamma its angle
// from w_o. A horizon is kept as cos e, e its elevation above the tangent line of its side; samples
// farther than R from x (the radius cut: the step membership), below the tangent plane, far off the
// slice or at x itself are skipped. V = sum |n_p| a / sum |n_p| a_open (the slices' own estimate of
// the open integral as normaliser), clamped to [0, 1]. The paper's A is visibility: V = A. The 4x4
// pattern rotates the slices and offsets the steps per pixel; box_filter.comp is the paper's 4x4
// denoiser, gtao_bounce.comp its multi-bounce fit.
//
// Uniforms (GtaoParams and R; src/ao/methods/gtao/gtao_gpu.cpp):
//   u_size        common.glsl
//   u_slices      slices per pixel, [1, 16]
//   u_steps       samples per side of a slice, [1, 32]
//   u_radius      R, world units
//   u_px_per_unit pixels per unit of x/(-z) (0.5 height / tan(fov/2))
//   u_rays        (ax, bx, ay, by): camera_direction(px, py) = (ax px + bx, ay py + by, -1)
// Buffers (gtao_internal.h's tables, entry [k][pattern] at k * 16 + pattern): binding 0 the slice
// directions (cos, sin) per slice k; binding 1 the step fractions per step j.
#include "common.glsl"
#include "gtao_shared.h"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, r32f) uniform writeonly image2D o_visibility;
layout(std430, binding = 0) readonly buffer Directions { vec2 u_directions[]; };
layout(std430, binding = 1) readonly buffer Steps { float u_step_t[]; };

uniform int u_slices;
uniform int u_steps;
uniform float u_radius;
uniform float u_px_per_unit;
uniform vec4 u_rays;

const float kPi = 3.14159265358979323846;
const float kHalfPi = 0.5 * kPi;

// acos on [-1, 1] by Abramowitz & Stegun 4.4.46 (gtao_shared.h), as the CPU kernel.
float fast_acos(float x) {
  const float a = min(abs(x), 1.0);
  float p = kAcosFit7;
  p = p * a + kAcosFit6;
  p = p * a + kAcosFit5;
  p = p * a + kAcosFit4;
  p = p * a + kAcosFit3;
  p = p * a + kAcosFit2;
  p = p * a + kAcosFit1;
  p = p * a + kAcosFit0;
  const float r = p * sqrt(1.0 - a);
  return x < 0.0 ? kPi - r : r;
}

void main() {
  const ivec2 pix = ivec2(gl_GlobalInvocationID.xy);
  if (pix.x >= u_size.x || pix.y >= u_size.y) return;
  if (!covered(pix)) {
    imageStore(o_visibility, pix, vec4(1.0));
    return;
  }
  const float d = depth_at(pix);
  const float fx = float(pix.x) + 0.5, fy = float(pix.y) + 0.5;
  // x rebuilt from the depth as its samples are, so x and its samples agree exactly on a plane.
  const vec3 p = vec3(d * (u_rays.x * fx + u_rays.y), d * (u_rays.z * fy + u_rays.w), -d);
  const vec3 n = texelFetch(u_normal, pix, 0).xyz;
  const int pattern = (pix.y & 3) * 4 + (pix.x & 3);
  const int pixel = pix.y * u_size.x + pix.x;
  const float inv = 1.0 / sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
  const vec3 w = -p * inv;  // w_o: from x to the eye
  const float radius_px = u_radius * u_px_per_unit / -p.z;
  const float r2 = u_radius * u_radius;
  // Continuous pixel coordinates stay below these (just inside the last pixel) along a slice.
  const float width_in = float(u_size.x) - 1e-3, height_in = float(u_size.y) - 1e-3;
  float sum_v = 0.0, sum_open = 0.0;
  for (int s = 0; s < u_slices; ++s) {
    const vec2 dir = u_directions[s * 16 + pattern];
    const float c = dir.x, si = dir.y;
    // The screen direction (c, si) (pixel y down) is the camera-space direction (c, -si, 0); with
    // w_o it spans the slice plane; its part orthogonal to w_o, o, is the slice's theta = +pi/2 axis.
    const float dw = c * w.x - si * w.y;
    vec3 o = vec3(c - dw * w.x, -si - dw * w.y, -dw * w.z);
    o *= 1.0 / sqrt(o.x * o.x + o.y * o.y + o.z * o.z);
    // The slice plane's axis, and n_p = n minus its axis part.
    const vec3 q = vec3(o.y * w.z - o.z * w.y, o.z * w.x - o.x * w.z, o.x * w.y - o.y * w.x);
    const float na = n.x * q.x + n.y * q.y + n.z * q.z;
    const vec3 np = n - na * q;
    const float len = sqrt(np.x * np.x + np.y * np.y + np.z * np.z);
    // gamma = angle of n_p from w_o (towards o when positive); cos gamma clamped at 0 so that a
    // normal facing away from the eye (at silhouettes) keeps the hemisphere on the visible side.
    const float cos_g = len > 0.0 ? clamp((np.x * w.x + np.y * w.y + np.z * w.z) / len, 0.0, 1.0) : 1.0;
    const float sign = np.x * o.x + np.y * o.y + np.z * o.z >= 0.0 ? 1.0 : -1.0;
    const float sin_g = sign * sqrt(1.0 - cos_g * cos_g);
    const float gamma = sign * fast_acos(cos_g);
    const float inv_np = len > 0.0 ? 1.0 / len : 0.0;
    // The tangent directions at theta = gamma + pi/2 (side +) and gamma - pi/2 (side -).
    const vec3 tangent_pos = -sin_g * w + cos_g * o, tangent_neg = sin_g * w - cos_g * o;
    // Clamp-to-edge along the slice: how far (pixels) each side runs before leaving the image.
    const float to_right = (width_in - fx) / c, to_left = fx / -c, to_bottom = (height_in - fy) / si, to_top = fy / -si;
    const float run_x_pos = c > 0.0 ? to_right : c < 0.0 ? to_left : kInfinity;
    const float run_x_neg = c > 0.0 ? fx / c : c < 0.0 ? (width_in - fx) / -c : kInfinity;
    const float run_y_pos = si > 0.0 ? to_bottom : si < 0.0 ? to_top : kInfinity;
    const float run_y_neg = si > 0.0 ? fy / si : si < 0.0 ? (height_in - fy) / -si : kInfinity;
    // The horizon search on both sides: the lowest cos e of the samples within R above the
    // tangent plane, cos e of a sample = its component along the side's tangent direction over the
    // length of its (along, up) part; 1 (the tangent plane itself) when none.
    float best[2] = float[2](1.0, 1.0);
    for (int side = 0; side < 2; ++side) {
      const float sgn = side == 0 ? 1.0 : -1.0;
      const vec3 tangent = side == 0 ? tangent_pos : tangent_neg;
      const float run = side == 0 ? min(run_x_pos, run_y_pos) : min(run_x_neg, run_y_neg);
      for (int j = 0; j < u_steps; ++j) {
        // At least one pixel from x, so the first sample is not x itself.
        const float dist = min(1.0 + u_step_t[j * 16 + pattern] * max(radius_px - 1.0, 0.0), run);
        const float off = sgn * dist;
        const ivec2 at = clamp(ivec2(int(fx + off * c), int(fy + off * si)), ivec2(0), u_size - 1);
        const float ds = depth_at(at);
        const vec3 v = vec3(ds * (u_rays.x * (float(at.x) + 0.5) + u_rays.y) - p.x, ds * (u_rays.z * (float(at.y) + 0.5) + u_rays.w) - p.y, -ds - p.z);
        const float vv = v.x * v.x + v.y * v.y + v.z * v.z;
        const float up = (v.x * n.x + v.y * n.y + v.z * n.z) * inv_np;
        const float along = v.x * tangent.x + v.y * tangent.y + v.z * tangent.z;
        // The radius cut; only samples above the tangent plane; a sample whose (along, up) covers
        // less than half of |v|^2 lies far off the slice; x's own pixel has no direction.
        const float in_frame = along * along + up * up;
        const bool use = vv < r2 && up > 0.0 && 2.0 * in_frame > vv && at.y * u_size.x + at.x != pixel;
        if (use) best[side] = min(best[side], along / sqrt(in_frame));
      }
    }
    // The inner integral between the horizons (h2 = gamma + pi/2 - e2, h1 = gamma - pi/2 + e1; a
    // horizon past the view vector is held at theta = 0: x is seen from the eye).
    const float c2 = clamp(best[0], -1.0, 1.0), c1 = clamp(best[1], -1.0, 1.0);
    const float e2 = fast_acos(c2), e1 = fast_acos(c1);
    const bool past2 = gamma + kHalfPi - e2 < 0.0, past1 = gamma - kHalfPi + e1 > 0.0;
    const float h2 = past2 ? 0.0 : gamma + kHalfPi - e2, h1 = past1 ? 0.0 : gamma - kHalfPi + e1;
    // cos(2 h - gamma) from cos e: cos 2e = 2c^2 - 1, sin 2e = 2c sqrt(1 - c^2).
    const float s2 = sqrt(max(1.0 - c2 * c2, 0.0)), s1 = sqrt(max(1.0 - c1 * c1, 0.0));
    const float cos2 = past2 ? cos_g : -((2.0 * c2 * c2 - 1.0) * cos_g + 2.0 * c2 * s2 * sin_g);
    const float cos1 = past1 ? cos_g : -((2.0 * c1 * c1 - 1.0) * cos_g - 2.0 * c1 * s1 * sin_g);
    const float a = 0.25 * (-cos1 + cos_g + 2.0 * h1 * sin_g) + 0.25 * (-cos2 + cos_g + 2.0 * h2 * sin_g);
    const float open = cos_g + gamma * sin_g;  // the inner integral of the open hemisphere
    sum_v += len * a;
    sum_open += len * open;
  }
  imageStore(o_visibility, pix, vec4(sum_open > 0.0 ? clamp(sum_v / sum_open, 0.0, 1.0) : 1.0));
}
