#version 430
// SPDX-License-Identifier: Apache-2.0
// Volumetric ambient occlusion, one invocation per pixel. Based on Szirmay-Kalos, Umenhoffer,
// Toth, Szecsi, Sbert, "Volumetric Ambient Occlusion for Real-Time Rendering and Games" (VAO),
// eq. 6-7 (the CPU kernel: src/ao/methods/volumetric/volumetric.cpp):
//
//   V(x) = |free part of S| / |S| ~ (1/F) sum_i dz_i                                   (eq. 7)
//
// S is the tangent sphere of radius R/2 centred at c = x + N R/2 (fig. 4). Its volume is summed as
// n pipes along the view axis through the Poisson-disk points (x_i, y_i) of its great disk
// perpendicular to the view axis (fig. 7), turned by the pixel's 4x4 interleaving angle (sec. 4.2).
// Pipe i enters the sphere at z_c - (R/2) h_i and leaves at z_c + (R/2) h_i, h_i = sqrt(1 - x_i^2 -
// y_i^2); its free length is
//   dz_i = clamp(z*_i - z_entry_i, 0, z_exit_i - z_entry_i)                            (fig. 7a-c)
// with z*_i the depth buffer at the pipe's pixel (VAO fig. 2c). With silhouette elimination (AT
// 4.3) a surface more than R in front of the entry is a distant foreground object: the pipe counts
// as free. F = R sum_i h_i (weighted importance) or 2Rn/3 (analytic; V is then clamped at 1). The
// paper's V is openness already.
//
// The pixel position of a pipe's point (c_x + o_x, c_y + o_y, c_z) is affine in the disk point, as
// the CPU kernel folds it: f_x = f_x0 + x_i a_x - y_i b_x, f_y = f_y0 - x_i a_y - y_i b_y.
//
// Uniforms (VolumetricParams and R; volumetric_gpu.cpp):
//   u_size, u_projection  common.glsl
//   u_samples     n, [1, 256]
//   u_half_radius R / 2, world units
//   u_far_limit   -R with silhouette elimination, -infinity without
//   u_inv_f       1 / F
//   u_bias        added to z* - z_entry, world units; 0 = automatic (screen_space.glsl depth_bias)
//   u_footprint   one pixel's footprint at unit depth
//   u_rotation[16] the 4x4 pattern's (cos, sin) about the view axis
//   u_thickness   with AO_SHEETS, one layer's sheets (screen_space.glsl)
// Buffers: binding 0, the disk points (x_i, y_i, h_i, 0) of make_disk_samples (unit disk).
#include "common.glsl"
#include "screen_space.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, r32f) uniform writeonly image2D o_visibility;
layout(std430, binding = 0) readonly buffer Disk { vec4 u_disk[]; };

uniform int u_samples;
uniform float u_half_radius;
uniform float u_far_limit;
uniform float u_inv_f;
uniform float u_bias;
uniform float u_footprint;
uniform vec2 u_rotation[16];

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
  const float hr = u_half_radius;
  const vec3 c = p + hr * n;  // fig. 4: the tangent sphere's centre
  const float inv = -1.0 / c.z, kx = inv * u_projection.x, ky = inv * u_projection.y;
  const float fx0 = c.x * kx + u_projection.z, fy0 = u_projection.w - c.y * ky;
  const float cax = rot.x * kx, cbx = rot.y * kx, cay = rot.y * ky, cby = rot.x * ky;
  const bool valid = c.z < 0.0;  // a centre behind the camera sees nothing: its pipes are free
  const vec2 max_pixel = vec2(u_size - 1);
  float free_length = 0.0;
  for (int i = 0; i < u_samples; ++i) {
    const float xi = hr * u_disk[i].x, yi = hr * u_disk[i].y;
    const float half_chord = hr * u_disk[i].z;  // (R/2) h_i = z_c - z_entry
    const float chord = 2.0 * half_chord;         // z_exit - z_entry
    const float fx = fx0 + xi * cax - yi * cbx, fy = fy0 - xi * cay - yi * cby;
    // As locate(): clamp-to-edge, free only behind the camera.
    const ivec2 at = ivec2(int(min(max(valid ? fx : 0.0, 0.0), max_pixel.x)), int(min(max(valid ? fy : 0.0, 0.0), max_pixel.y)));
    // z* - z_entry = (z* - z_c) + (R/2) h_i.
    const float to_surface = (valid ? depth_at(at) + c.z : kInfinity) + half_chord + bias;
    float dz = min(max(to_surface, 0.0), chord);  // fig. 7 a-c
#ifdef AO_SHEETS
    if (valid && to_surface < chord) {
      // One layer's sheets (volumetric_kernel.cpp's two layers with nothing behind): the solid in the
      // pipe is [dz, end) from its entry, and past the sheet's thickness solid only where the sheet
      // hides it from x, judged at the gap's middle, the pipe's point at depth z_entry + (end + chord) / 2.
      const float zs = depth_at(at);
      float end = min(max(zs + u_thickness + c.z + half_chord, 0.0), chord);
      if (end < chord) {
        const vec3 mid = vec3(c.x + xi * rot.x - yi * rot.y, c.y + xi * rot.y + yi * rot.x, c.z + half_chord - 0.5 * (end + chord));
        if (sheet_hides(at, vec3(mid.xy, -zs), p, mid, bias)) end = chord;
      }
      dz = chord - max(end - dz, 0.0);
    }
#endif
    const bool distant = to_surface < u_far_limit && to_surface > -1e30;
    free_length += distant ? chord : dz;
  }
  imageStore(o_visibility, pix, vec4(min(free_length * u_inv_f, 1.0)));  // eq. 7; analytic F can overshoot 1
}
