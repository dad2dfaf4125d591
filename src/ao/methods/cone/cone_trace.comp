#version 430
// SPDX-License-Identifier: Apache-2.0
// Voxel cone traced ambient occlusion on the world grid, one invocation per pixel. Based on E. C.
// Dalla Favera and W. Celes, "Ambient occlusion using cone tracing with scene voxelization",
// SIBGRAPI 2012, sec. III-C (the CPU kernel, with the same tables: src/ao/methods/cone/cone_world.cpp).
//
// Per pixel, the hemisphere about the normal is sampled by cones (Fig. 5a); each cone by a chain
// of spheres tangent to each other and inscribed in it out to R_max (Fig. 5b), plus a filler
// sphere in what a jittered (shortened) chain leaves of [0, R_max]; each sphere's obstructed
// fraction is estimated from prisms along the grid's columns through the Poisson-disk points of
// its great disk, their solid lengths counted with masks and bitCount (sec. III-C1, Figs. 6-7);
// spheres combine front to back, T *= 1 - f (sec. III-C2, Fig. 8), until T <= 1e-4 (the rest could
// lower V by less than that); V is the mean of T over the cones (cells of equal measure). The
// paper computes the blocked fraction; V = 1 - it. Spheres that start nearer the apex than 1.5
// voxels are skipped (the voxelized surface itself fills them).
//
// A prism's solid length counts the voxels strictly inside [z_lo, z_hi) whole and the two end
// voxels by the part of them inside (the paper counts whole bits; the fractions remove a bias of
// up to a voxel for the small spheres near the apex).
//
// Uniforms (src/ao/methods/cone/cone_gpu.cpp):
//   u_size                 common.glsl
//   u_eye, u_basis_x/y/z   the camera (world), to take the G-buffer's points and normals to world space
//   u_origin, u_inv_size   the grid (as cone_voxelize.vert)
//   u_columns, u_depth_bits
//   u_cones, u_per_cone    cones per pixel; spheres per cone including the filler
//   u_prisms               prisms per sphere
//   u_period               the jitter table's period P (pixel (x, y) takes slot (y % P) P + x % P)
//   u_key                  -1: every pixel; k >= 0: only the pixels whose side (buffer 1) is k, which
//                          the grid of buffer 0 was built for (the back sides of open meshes: one pass
//                          per grid, each writing its pixels)
// Buffers:
//   0  the grid's words (cone_pack.comp's layout)
//   1  per pixel (row-major) the index of its side's grid (cone_sides_internal.h PixelSides::key_of)
//   2  per slot: (cos, sin) of the prism pattern's turn, then per cone (axis x, y, z in the
//      normal's frame, chain scale s), make_cone_pattern's table
//   3  per sphere slot j of a cone: (dist_a, dist_b, rad_a, rad_b), (use_a, use_b, k, 0): its
//      distance along the axis dist_a s + dist_b, radius scale min(rad_a s + rad_b, 1), sampled when
//      use_a s + use_b >= 0, and which sphere of the chain k its prisms use
//   4  per chain sphere k: (rx, ry, rz in voxels, sum of its prisms' chords in voxels)
//   5  per prism s: (u, v) on the unit disk, then per chain sphere k the prisms' half chords in voxels
#include "common.glsl"
#include "cone_shared.h"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, r32f) uniform writeonly image2D o_visibility;
layout(std430, binding = 0) readonly buffer Grid { uint u_words[]; };
layout(std430, binding = 1) readonly buffer Keys { uint u_keys[]; };
layout(std430, binding = 2) readonly buffer Pattern { vec4 u_pattern[]; };
layout(std430, binding = 3) readonly buffer Lanes { vec4 u_lanes[]; };
layout(std430, binding = 4) readonly buffer Spheres { vec4 u_spheres[]; };
layout(std430, binding = 5) readonly buffer Prisms { float u_prism[]; };

uniform vec3 u_eye, u_basis_x, u_basis_y, u_basis_z;
uniform vec3 u_origin, u_inv_size;
uniform ivec2 u_columns;
uniform int u_depth_bits;
uniform int u_cones, u_per_cone, u_prisms, u_period;
uniform int u_key;

uint bit(uint base, int k) { return (u_words[base + uint(k >> 5)] >> uint(k & 31)) & 1u; }

// Set voxels among [k0, k1) of the column at `base` (voxelize.h count_bits).
int count_bits(uint base, int k0, int k1) {
  if (k1 <= k0) return 0;
  const int w0 = k0 >> 5, w1 = (k1 - 1) >> 5;
  const uint lo = 0xffffffffu << uint(k0 & 31), hi = 0xffffffffu >> uint(31 - ((k1 - 1) & 31));
  if (w0 == w1) return bitCount(u_words[base + uint(w0)] & lo & hi);
  int n = bitCount(u_words[base + uint(w0)] & lo) + bitCount(u_words[base + uint(w1)] & hi);
  for (int w = w0 + 1; w < w1; ++w) n += bitCount(u_words[base + uint(w)]);
  return n;
}

// Length of [zlo, zhi) (voxels along the column) covered by solid voxels (cone_kernel_internal.h).
float solid_length(uint base, float zlo, float zhi) {
  zlo = max(zlo, 0.0);
  zhi = min(zhi, float(u_depth_bits));
  if (!(zhi > zlo)) return 0.0;
  const int k0 = int(zlo), k1 = min(int(zhi), u_depth_bits - 1);
  if (k0 >= k1) return float(bit(base, k0)) * (zhi - zlo);
  return float(bit(base, k0)) * (float(k0 + 1) - zlo) + float(count_bits(base, k0 + 1, k1)) + float(bit(base, k1)) * (zhi - float(k1));
}

vec3 to_world(vec3 v) { return u_basis_x * v.x + u_basis_y * v.y + u_basis_z * v.z; }

void main() {
  const ivec2 pix = ivec2(gl_GlobalInvocationID.xy);
  if (pix.x >= u_size.x || pix.y >= u_size.y) return;
  if (u_key >= 0 && int(u_keys[pix.y * u_size.x + pix.x]) != u_key) return;
  if (!covered(pix)) {
    imageStore(o_visibility, pix, vec4(1.0));
    return;
  }
  const vec3 pos = to_world(texelFetch(u_position, pix, 0).xyz) + u_eye;
  const vec3 n = normalize(to_world(texelFetch(u_normal, pix, 0).xyz));
  vec3 t, b;
  frame_from_normal(n, t, b);
  const int slot = (pix.y & (u_period - 1)) * u_period + (pix.x & (u_period - 1));
  const int slot_base = slot * (1 + u_cones);
  const vec2 rot = u_pattern[slot_base].xy;
  // The pixel's point in voxels.
  const vec3 g = vec3((pos.x - u_origin.x) * u_inv_size.x, (pos.z - u_origin.z) * u_inv_size.y, (pos.y - u_origin.y) * u_inv_size.z);
  const int prism_half = 2 * u_prisms;  // the half chords follow the disk points
  const float weight = 1.0 / float(u_cones);  // every cone stands for a cell of equal measure
  float v = 0.0;
  for (int c = 0; c < u_cones; ++c) {
    const vec4 cone = u_pattern[slot_base + 1 + c];
    // The cone's axis in world space, then in voxels along (column x, column y, k) = world (x, z, y).
    const vec3 w = t * cone.x + b * cone.y + n * cone.z;
    const vec3 axis = vec3(w.x * u_inv_size.x, w.z * u_inv_size.y, w.y * u_inv_size.z);
    const float s = cone.w;
    float tr = 1.0;
    for (int j = 0; j < u_per_cone && tr > kConeOpaque; ++j) {
      const vec4 la = u_lanes[2 * j], lb = u_lanes[2 * j + 1];
      if (!(fma(lb.x, s, lb.y) >= 0.0)) continue;  // a sphere too near the apex, or a filler of no size
      const float d = fma(la.x, s, la.y);
      const vec3 centre = vec3(fma(axis.x, d, g.x), fma(axis.y, d, g.y), fma(axis.z, d, g.z));
      const float scale = min(fma(la.z, s, la.w), 1.0);
      const int k = int(lb.z);
      const vec4 sphere = u_spheres[k];
      const float rx = sphere.x * scale, ry = sphere.y * scale;
      // Sec. III-C1: the sphere's obstructed fraction, solid length over chord length of its prisms.
      float solid = 0.0;
      for (int p = 0; p < u_prisms; ++p) {
        const float du = u_prism[2 * p], dv = u_prism[2 * p + 1];
        // The prism pattern turned by the pixel's angle (the CPU's fused forms).
        const float pu = fma(du, rot.x, -(dv * rot.y)), pv = fma(du, rot.y, dv * rot.x);
        const float h = u_prism[prism_half + k * u_prisms + p] * scale;
        const float fx = centre.x + pu * rx, fy = centre.y + pv * ry;
        if (!(fx >= 0.0 && fy >= 0.0 && fx < float(u_columns.x) && fy < float(u_columns.y))) continue;
        const uint base = uint((int(fy) * u_columns.x + int(fx)) * (u_depth_bits / 32));
        solid += solid_length(base, centre.z - h, centre.z + h);
      }
      const float chord = sphere.w * scale;
      const float f = chord > 0.0 ? min(1.0, solid / chord) : 0.0;
      tr *= 1.0 - f;  // sec. III-C2, Fig. 8: front to back
    }
    v += weight * tr;
  }
  imageStore(o_visibility, pix, vec4(clamp(v, 0.0, 1.0)));
}
