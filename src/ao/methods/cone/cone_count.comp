#version 430
// SPDX-License-Identifier: Apache-2.0
// The voxel grid's statistics after cone_voxelize.frag (VoxelStats): solid voxels, and columns
// whose parity ends odd (their last voxel is set: the geometry is not closed there).
//
// Uniforms: u_columns (nx, ny), u_depth_bits. Buffer 0: the grid (cone_voxelize.frag's layout);
// buffer 1: the counters.

layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = 0) readonly buffer Grid { uint u_words[]; };
layout(std430, binding = 1) buffer Counters { uint u_triangles; uint u_fragments; uint u_set_voxels; uint u_odd_columns; };

uniform ivec2 u_columns;
uniform int u_depth_bits;

void main() {
  const ivec2 col = ivec2(gl_GlobalInvocationID.xy);
  if (col.x >= u_columns.x || col.y >= u_columns.y) return;
  const int words = u_depth_bits / 32;
  const uint base = uint((col.y * u_columns.x + col.x) * words);
  uint set = 0u;
  for (int w = 0; w < words; ++w) set += uint(bitCount(u_words[base + uint(w)]));
  if (set != 0u) atomicAdd(u_set_voxels, set);
  if ((u_words[base + uint(words - 1)] >> 31) != 0u) atomicAdd(u_odd_columns, 1u);
}
