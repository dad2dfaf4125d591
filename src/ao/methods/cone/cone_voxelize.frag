#version 430
// SPDX-License-Identifier: Apache-2.0
// Solid voxelization by parity, fragment stage (see cone_voxelize.vert and .geom): one fragment per
// column centre (i + 0.5, j + 0.5) of the triangle's grown box. A centre inside the triangle (the
// CPU's edge functions and tie rule: E > 0, or E = 0 on an edge whose normal points right, or
// straight up) makes a fragment at voxel coordinate a; it flips every voxel whose centre b + 0.5
// lies beyond a, b >= ceil(a - 0.5) (clamped to the column's start), by XOR-ing that depth-slab
// mask into the column's words (sec. III-B: the parity of the crossings below a voxel says whether
// it is inside). The paper XORs through the framebuffer's logic operation into colour targets; an
// atomic XOR into the grid's buffer is the same operation without the targets' 1024-bit limit
// per pass (and works where a driver applies no logic operation to integer targets: llvmpipe). A
// fragment beyond the column's end flips nothing. The CPU voxelizer toggles one bit per fragment
// and scans each column with a prefix XOR at the end: the same bits, as XOR is associative and
// commutative.
//
// The grid: column (i, j)'s bit b in word (j nx + i) * depth_bits / 32 + b / 32, bit b % 32 (the
// CPU grid's layout in 32-bit words). Uniforms: u_columns (nx, ny); u_depth_bits (voxels per
// column, a multiple of 32 in [32, 1024]).

flat in dvec3 g_edge[3];
flat in dvec3 g_plane;
flat in dvec2 g_origin;

uniform ivec2 u_columns;
uniform int u_depth_bits;

layout(std430, binding = 0) buffer Grid { uint u_words[]; };
layout(std430, binding = 1) buffer Counters { uint u_triangles; uint u_fragments; uint u_set_voxels; uint u_odd_columns; };

bool inside(dvec3 e, dvec2 c) {
  const double v = e.x * c.x + e.y * c.y + e.z;
  return v > 0.0LF || (v == 0.0LF && (e.x > 0.0LF || (e.x == 0.0LF && e.y > 0.0LF)));
}

void main() {
  const dvec2 c = dvec2(gl_FragCoord.xy);  // the column centre (i + 0.5, j + 0.5), exactly
  if (!(inside(g_edge[0], c) && inside(g_edge[1], c) && inside(g_edge[2], c))) discard;
  // The voxel coordinate of the fragment, the plane's affine form as the CPU voxelizer evaluates
  // it (GCC fuses it into two multiply-adds; so does this).
  const double a = fma(g_plane.z, c.y - g_origin.y, fma(g_plane.y, c.x - g_origin.x, g_plane.x));
  const double first = ceil(a - 0.5LF);
  if (first >= double(u_depth_bits)) discard;
  const int b = first <= 0.0LF ? 0 : int(first);
  atomicAdd(u_fragments, 1u);
  const ivec2 col = ivec2(gl_FragCoord.xy);
  const int words = u_depth_bits / 32;
  const uint base = uint((col.y * u_columns.x + col.x) * words);
  atomicXor(u_words[base + uint(b >> 5)], 0xffffffffu << uint(b & 31));
  for (int w = (b >> 5) + 1; w < words; ++w) atomicXor(u_words[base + uint(w)], 0xffffffffu);
}
