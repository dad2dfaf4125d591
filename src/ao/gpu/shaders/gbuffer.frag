#version 430
// SPDX-License-Identifier: Apache-2.0
// G-buffer rasterization, fragment stage: one G-buffer texel per pixel centre, the nearest
// surface winning by depth (the depth buffer holds u_clip.z / depth, written here exactly from the
// fragment's own depth, so that the test compares the same depths the G-buffer stores).
//
// Uniforms:
//   u_size        image size, pixels
//   u_tan_half    tan(fov/2) and the aspect (Camera::camera_direction)
//   u_clip.z      the near plane's depth (gbuffer.vert)
//   u_object      1 + the object's index in Scene::objects()
//   u_albedo      the mesh's albedo
//   u_geometric   1: the normal channel holds the geometric normal (SurfaceNormal::Geometric)

in vec3 g_normal;
in vec2 g_uv;
flat in vec3 g_geometric;
flat in vec4 g_plane;
flat in int g_triangle;

uniform ivec2 u_size;
uniform vec2 u_tan_half;
uniform vec3 u_clip;
uniform uint u_object;
uniform vec3 u_albedo;
uniform int u_geometric;

layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_normal;
layout(location = 2) out vec4 o_albedo;
layout(location = 3) out uint o_object;
layout(location = 4) out uint o_triangle;
layout(location = 5) out vec2 o_uv;
layout(location = 6) out float o_depth;

void main() {
  // Camera::camera_direction through the pixel centre (texel row = image row: gbuffer.vert).
  const vec2 px = gl_FragCoord.xy;
  const vec3 dir = vec3((2.0 * px.x / float(u_size.x) - 1.0) * u_tan_half.x * u_tan_half.y, (1.0 - 2.0 * px.y / float(u_size.y)) * u_tan_half.x, -1.0);
  // The pixel's ray met with the triangle's plane: the point a ray tracer returns. Edge-on
  // triangles (no finite intersection) are the same pixels whose rasterization is edge-on: dropped.
  const float along = dot(g_plane.xyz, dir);
  const vec3 pc = dir * (g_plane.w / along);
  if (!(pc.z < 0.0) || isinf(pc.z)) discard;
  // render_gbuffer: AO is for the side facing the viewer, so the geometric normal is turned towards
  // the camera and the shading normal onto its side; where the vertex normals cancel, the
  // geometric one.
  const vec3 ng = dot(g_geometric, pc) > 0.0 ? -g_geometric : g_geometric;
  vec3 n = ng;
  if (u_geometric == 0) {
    const float len = length(g_normal);
    n = len > 0.0 ? g_normal / len : vec3(0.0);
    if (dot(n, ng) < 0.0) n = -n;
    if (!(dot(n, n) > 0.25)) n = ng;
  }
  o_position = vec4(pc, 1.0);
  o_normal = vec4(n, 0.0);
  o_albedo = vec4(u_albedo, 1.0);
  o_object = u_object;
  o_triangle = uint(g_triangle);
  o_uv = g_uv;
  o_depth = -pc.z;
  gl_FragDepth = clamp(u_clip.z / -pc.z, 0.0, 1.0);
}
