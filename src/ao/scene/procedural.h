// SPDX-License-Identifier: Apache-2.0
// Built-in scenes: the default demo and analytic test scenes with known AO, plus the shape
// builders they are made of (also used by tests to build their own configurations).
// World space is y-up. All shapes are triangle meshes with outward (or, for rooms, inward)
// facing counter-clockwise triangles and exact normals.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "ao/scene/mesh.h"

namespace ao {

/// Names accepted by make_builtin_scene: "default", "plane", "wedge", "sphere-on-plane", "box-room",
/// "displaced".
std::vector<std::string> builtin_scene_names();
bool is_builtin_scene(std::string_view name);
/// The built-in scenes whose Scene::analytic carries an implicit surface: plane, wedge, sphere-on-plane.
std::vector<std::string> builtin_scenes_with_implicit_surface();
/// The built-in scenes whose Scene::analytic carries a height field: displaced.
std::vector<std::string> builtin_scenes_with_height_field();

/// A built-in scene by name; validated and ready to use. Throws InputError for an unknown name.
///  - default: the demo. A ground plane with a sphere resting on it (contact shadow), a rotated box
///    and stairs (creases), a deep square pit, thin pillars, a torus, a wall, and a field of small
///    cubes, so occlusion shows at several scales.
///  - plane: a 40 x 40 square at y = 0. Every point has V = 1. Implicit: the half-space y >= 0.
///  - wedge: two 200 x 100 half-planes at 90 degrees, the floor y = 0 (z >= 0) and the wall z = 0
///    (y >= 0), meeting along the x axis. On the crease, about the bisector normal, V = 1/2.
///    Implicit: y >= 0 and z >= 0.
///  - sphere-on-plane: a unit sphere resting on a 40 x 40 plane at the origin. Implicit: y >= 0
///    and outside the sphere.
///  - box-room: a closed 4 x 3 x 5 room seen from inside, with a box and a sphere on its floor.
///    With R larger than the room, every point inside has V = 0.
///  - displaced: an 8 x 8 floor displaced by a grid of smooth domes (make_bump_map: 4 x 4 domes
///    0.2 high per 2 x 2 units), tessellated at the map's resolution (one vertex per texel,
///    131k triangles), with a sphere and a box standing on it. Height field: the floor's map,
///    period and amplitude over the plane y = 0 (the meshes are the real geometry; the
///    description is what the height-field characteristic function reads).
Scene make_builtin_scene(std::string_view name);

/// Quad p0 p1 p2 p3 (counter-clockwise seen from its front) as two triangles with a flat normal.
Mesh make_quad(Vec3 p0, Vec3 p1, Vec3 p2, Vec3 p3, Vec3 albedo = {0.8f, 0.8f, 0.8f});
/// Closed axis-aligned box [lo, hi], rotated by `yaw_deg` about the vertical axis through its
/// centre; outward normals, or inward ones when `inward` (a room).
Mesh make_box(Vec3 lo, Vec3 hi, Vec3 albedo = {0.8f, 0.8f, 0.8f}, float yaw_deg = 0.0f, bool inward = false);
/// Closed UV sphere with smooth normals.
Mesh make_sphere(Vec3 center, float radius, int segments = 48, int rings = 24, Vec3 albedo = {0.8f, 0.8f, 0.8f});
/// Closed vertical cylinder (with caps) standing on `base`.
Mesh make_cylinder(Vec3 base, float radius, float height, int segments = 24, Vec3 albedo = {0.8f, 0.8f, 0.8f});
/// Torus lying flat (axis = y) with major radius `major` and tube radius `minor`.
Mesh make_torus(Vec3 center, float major, float minor, int segments = 48, int sides = 16, Vec3 albedo = {0.8f, 0.8f, 0.8f});

/// Appends `src` to `dst` (same material: dst's albedo is kept).
void append_mesh(Mesh& dst, const Mesh& src);

}  // namespace ao
