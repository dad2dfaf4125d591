#version 430
// SPDX-License-Identifier: Apache-2.0
// Solid voxelization by parity, geometry stage (see cone_voxelize.vert). Every triangle, front and
// back faces alike (sec. III-B), is drawn as the box of columns its bounding box covers, grown by
// one column: the fragment stage then decides coverage itself, at each column centre, with the
// CPU voxelizer's exact edge functions and tie rule (in double precision), rather than leaving it
// to the rasterizer's snapped sub-pixel vertices. So both backends set the same voxels, and two
// triangles sharing an edge give a centre on that edge to exactly one of them (watertight).
//
// Per triangle it passes on, in double: the three edge functions E(x, y) = A x + B y + C of the
// directed edges, negated for clockwise triangles (so inside is E > 0), and the plane of the
// voxel coordinate a over the column coordinates. It also counts the triangles the CPU voxelizer
// would rasterize (those whose box covers a column centre of the grid; VoxelStats::triangles).
//
// Uniforms: u_columns (nx, ny). Buffer 1: the voxelization's counters (triangles, fragments,
// solid voxels, odd columns); with NO_GEOMETRY_COUNTER defined (a GPU that offers this stage no
// storage buffers) the triangles are not counted.

layout(triangles) in;
layout(triangle_strip, max_vertices = 4) out;

in vec3 v_grid[];

uniform ivec2 u_columns;

#ifndef NO_GEOMETRY_COUNTER
layout(std430, binding = 1) buffer Counters { uint u_triangles; uint u_fragments; uint u_set_voxels; uint u_odd_columns; };
#endif

flat out dvec3 g_edge[3];  // (A, B, C) per edge
flat out dvec3 g_plane;    // (a0 at (x0, y0), da/dx, da/dy)
flat out dvec2 g_origin;   // (x0, y0)

void main() {
  const vec3 t0 = v_grid[0], t1 = v_grid[1], t2 = v_grid[2];
  // The CPU's finish_visible: no column centre (i + 0.5, j + 0.5) of the grid inside the box.
  const float xmin = min(t0.x, min(t1.x, t2.x)), xmax = max(t0.x, max(t1.x, t2.x));
  const float ymin = min(t0.y, min(t1.y, t2.y)), ymax = max(t0.y, max(t1.y, t2.y));
  if (!(xmax >= 0.5 && xmin <= float(u_columns.x) - 0.5)) return;
  const float j0 = ceil(ymin - 0.5), j1 = floor(ymax - 0.5);
  if (j1 < 0.0 || j0 > float(u_columns.y - 1) || j0 > j1) return;
#ifndef NO_GEOMETRY_COUNTER  // GL 4.3 lets a GPU offer no storage buffers to this stage
  atomicAdd(u_triangles, 1u);
#endif
  const double x0 = t0.x, y0 = t0.y;
  const double area2 = (double(t1.x) - x0) * (double(t2.y) - y0) - (double(t2.x) - x0) * (double(t1.y) - y0);
  if (area2 == 0.0LF) return;  // edge-on: no column centre lies inside
  const double sign = area2 < 0.0LF ? -1.0LF : 1.0LF;  // back faces count as much as front faces
  const vec3 t[3] = vec3[3](t0, t1, t2);
  for (int e = 0; e < 3; ++e) {
    const double px = t[e].x, py = t[e].y, qx = t[(e + 1) % 3].x, qy = t[(e + 1) % 3].y;
    g_edge[e] = sign * dvec3(py - qy, qx - px, px * qy - py * qx);
  }
  const double da1 = double(t1.z) - double(t0.z), da2 = double(t2.z) - double(t0.z);
  const double dadx = (da1 * (double(t2.y) - y0) - da2 * (double(t1.y) - y0)) / area2;
  const double dady = (da2 * (double(t1.x) - x0) - da1 * (double(t2.x) - x0)) / area2;
  g_plane = dvec3(double(t0.z), dadx, dady);
  g_origin = dvec2(x0, y0);
  // The box grown by one column, in clip space (columns map to pixels of the nx x ny viewport).
  const vec2 lo = (vec2(xmin, ymin) - 1.0) / vec2(u_columns) * 2.0 - 1.0, hi = (vec2(xmax, ymax) + 1.0) / vec2(u_columns) * 2.0 - 1.0;
  const vec2 corner[4] = vec2[4](lo, vec2(hi.x, lo.y), vec2(lo.x, hi.y), hi);
  for (int k = 0; k < 4; ++k) {
    gl_Position = vec4(corner[k], 0.0, 1.0);
    EmitVertex();
  }
  EndPrimitive();
}
