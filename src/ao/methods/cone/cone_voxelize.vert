#version 430
// SPDX-License-Identifier: Apache-2.0
// Solid voxelization by parity, vertex stage (then cone_voxelize.geom, .frag). Based on Eisemann & Decoret, "Single-pass GPU solid
// voxelization for real-time applications" (GI 2008), as used by Dalla Favera & Celes, "Ambient
// occlusion using cone tracing with scene voxelization" (SIBGRAPI 2012), sec. III-B; the CPU
// voxelizer: src/ao/methods/cone/voxelize.cpp (world grid).
//
// The world grid's columns run along world y over the scene's bounds: a world point p is at
// column coordinates x = (p.x - origin.x) / voxel_x, y = (p.z - origin.z) / voxel_z and voxel
// coordinate a = (p.y - origin.y) / voxel_y along its column, computed as the CPU does (the
// difference, then the product with the reciprocal size), so both rasterize the same triangles.
//
// Uniforms (src/ao/methods/cone/cone_gpu.cpp):
//   u_instance, u_to_world[4]  as gbuffer.vert: an instance's Affine3 columns c0, c1, c2, c3
//   u_origin        world point of voxel coordinate (0, 0, 0)
//   u_inv_size      1 / voxel size along (column x = world x, column y = world z, k = world y)
//   u_columns       (nx, ny)

layout(location = 0) in vec3 a_position;

uniform int u_instance;
uniform vec3 u_to_world[4];
uniform vec3 u_origin;
uniform vec3 u_inv_size;
uniform ivec2 u_columns;

out vec3 v_grid;  // (x, y, a): column coordinates and voxel coordinate along the column

void main() {
  vec3 p = a_position;
  if (u_instance != 0) p = u_to_world[0] * p.x + u_to_world[1] * p.y + u_to_world[2] * p.z + u_to_world[3];
  v_grid = vec3((p.x - u_origin.x) * u_inv_size.x, (p.z - u_origin.z) * u_inv_size.y, (p.y - u_origin.y) * u_inv_size.z);
  gl_Position = vec4(v_grid.xy / vec2(u_columns) * 2.0 - 1.0, 0.0, 1.0);
}
