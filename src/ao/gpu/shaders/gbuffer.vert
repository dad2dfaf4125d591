#version 430
// SPDX-License-Identifier: Apache-2.0
// G-buffer rasterization, vertex stage (src/ao/gpu/gbuffer.cpp draws one object of the scene per
// call). Conventions of docs/gbuffer.md and gbuffer/render_gbuffer.cpp: world -> camera space is
// q = basis^T (p - eye) (Camera::world_to_camera_point), camera space right-handed looking down -z.
// An instance's vertices go through its transform first, its vertex normals through the
// transform's cofactor matrix, renormalised (flatten_instances).
//
// Uniforms:
//   u_instance          1: apply u_to_world / u_normal_to_world; 0: the mesh is in world space
//   u_to_world[4]       columns c0, c1, c2 and translation c3 of the instance's Affine3
//   u_normal_to_world[3] columns of its cofactor matrix
//   u_eye, u_basis_x/y/z  the camera: eye and Camera::basis() (x right, y up, z backwards), world
//   u_clip              x: 1 / (tan(fov/2) aspect), y: 1 / tan(fov/2), z: the near plane's depth

layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;

uniform int u_instance;
uniform vec3 u_to_world[4];
uniform vec3 u_normal_to_world[3];
uniform vec3 u_eye, u_basis_x, u_basis_y, u_basis_z;
uniform vec3 u_clip;

out vec3 v_world;   // world position (the geometric normal is taken in world space, as the CPU does)
out vec3 v_camera;  // camera-space position
out vec3 v_normal;  // camera-space vertex normal (unit)
out vec2 v_uv;

vec3 to_camera(vec3 w) { return vec3(dot(w, u_basis_x), dot(w, u_basis_y), dot(w, u_basis_z)); }

void main() {
  vec3 p = a_position, n = a_normal;
  if (u_instance != 0) {
    p = u_to_world[0] * p.x + u_to_world[1] * p.y + u_to_world[2] * p.z + u_to_world[3];
    n = normalize(u_normal_to_world[0] * n.x + u_normal_to_world[1] * n.y + u_normal_to_world[2] * n.z);
  }
  v_world = p;
  v_camera = to_camera(p - u_eye);
  v_normal = to_camera(n);
  v_uv = a_uv;
  // Perspective with the image's row 0 at the top of the framebuffer (y negated: texel row r is
  // image row r, as the CPU's images) and clip z = near: clip space keeps depth >= near, and the
  // fragment stage writes its own depth (gbuffer.frag).
  gl_Position = vec4(v_camera.x * u_clip.x, -v_camera.y * u_clip.y, u_clip.z, -v_camera.z);
}
