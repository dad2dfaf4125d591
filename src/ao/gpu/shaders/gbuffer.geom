#version 430
// SPDX-License-Identifier: Apache-2.0
// G-buffer rasterization, geometry stage: the per-triangle values the fragment stage needs, as
// render_gbuffer's CameraTriangle holds them. The unit geometric normal is taken in world space,
// as wound (counter-clockwise seen from the front), then turned into camera space; the plane of the
// camera-space triangle (normal nq, offset dq = nq . q0) lets each fragment meet its pixel's ray
// with the triangle exactly, as the ray tracer's hit does.
//
// Uniforms: u_basis_x/y/z, the camera's basis in world space (as gbuffer.vert).

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;

in vec3 v_world[];
in vec3 v_camera[];
in vec3 v_normal[];
in vec2 v_uv[];

uniform vec3 u_basis_x, u_basis_y, u_basis_z;

out vec3 g_normal;
out vec2 g_uv;
flat out vec3 g_geometric;  // unit geometric normal, camera space, as wound
flat out vec4 g_plane;      // camera-space plane: xyz normal (not unit), w offset
flat out int g_triangle;    // index of the triangle in its mesh

vec3 to_camera(vec3 w) { return vec3(dot(w, u_basis_x), dot(w, u_basis_y), dot(w, u_basis_z)); }

void main() {
  const vec3 ng = to_camera(normalize(cross(v_world[1] - v_world[0], v_world[2] - v_world[0])));
  const vec3 nq = cross(v_camera[1] - v_camera[0], v_camera[2] - v_camera[0]);
  for (int k = 0; k < 3; ++k) {
    gl_Position = gl_in[k].gl_Position;
    g_normal = v_normal[k];
    g_uv = v_uv[k];
    g_geometric = ng;
    g_plane = vec4(nq, dot(nq, v_camera[0]));
    g_triangle = gl_PrimitiveIDIn;
    EmitVertex();
  }
  EndPrimitive();
}
