// SPDX-License-Identifier: Apache-2.0
// What a mesh's connectivity says about the space around it: its boundary edges (a closed surface
// has none), the side its closed surface encloses, and whether a point lies inside it. The cone
// method's voxelization (methods/cone/mesh_closure.h) and the second depth layer
// (gbuffer/render_gbuffer.h) read them. Code: topology.cpp.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "ao/scene/mesh.h"

namespace ao {

/// The edges of one mesh, its vertices welded by exact position (so that meshes whose faces carry
/// their own copies of shared corners, as make_box's, are as closed as their surfaces are).
struct MeshEdges {
  std::vector<std::uint32_t> weld;  ///< Per vertex: its welded vertex, numbered from 0.
  std::uint32_t welded = 0;         ///< Welded vertices (distinct positions).
  std::size_t edges = 0;            ///< Distinct undirected edges.
  /// One directed edge (vertex indices, as a triangle lists it) per edge used by an odd number of
  /// triangles (a closed 2-manifold uses each edge twice).
  std::vector<std::array<std::uint32_t, 2>> boundary;
  std::vector<std::uint32_t> boundary_triangle;  ///< Per boundary edge: the triangle that lists it.
};

/// The edges of `m`.
MeshEdges mesh_edges(const Mesh& m);

/// The volume enclosed by `m` (in its own space), signed: positive when its triangles' fronts face
/// out of what it encloses. Meaningful for a closed mesh only.
double signed_volume(const Mesh& m);

/// Whether `p` (world space) lies inside `object` (one of scene.objects()), whose mesh must be
/// closed: an odd number of its triangles crossed by a ray from p.
bool inside_closed_object(const Scene& scene, const SceneObject& object, Vec3 p);

/// Per mesh of `scene`: which side of its triangles a ray leaves it through when it is a solid.
/// +1: a closed mesh whose fronts face out (a ray leaves it through a back face), -1: a closed mesh
/// whose fronts face in (through a front face), 0: an open mesh (no solid).
std::vector<std::int8_t> closed_mesh_sides(const Scene& scene);

/// Per object of Scene::objects(): how to read which side of an open mesh's triangle a ray meets,
/// so that the reading does not depend on the winding a file happened to give it. +1: as wound,
/// -1: turned over, so that its fronts face out of what it encloses as seen from its box's centre
/// (signed_volume > 0: a bowl's or a gutter's outside, a scan's skin); 0: a flat mesh (no volume
/// either way), whose every side a ray from the eye meets is taken for its front; and 0 for a
/// closed mesh (closed_mesh_sides reads it). `mesh_sides` as closed_mesh_sides gives.
std::vector<std::int8_t> open_mesh_facings(const Scene& scene, std::span<const std::int8_t> mesh_sides);

/// Per object of Scene::objects(): 1 for a closed mesh around `eye` (a room: what it encloses is air,
/// and its solid is everything outside it), 0 otherwise. `mesh_sides` as closed_mesh_sides gives.
std::vector<std::uint8_t> closed_objects_around(const Scene& scene, std::span<const std::int8_t> mesh_sides, Vec3 eye);

/// Per object of Scene::objects(): closed_mesh_sides's answer for its mesh (`mesh_sides`), turned
/// by an instance's transform that mirrors, and 0 for a room (`rooms`, as closed_objects_around
/// gives for the eye: a ray from the eye leaves it but never enters).
std::vector<std::int8_t> solid_exit_sides(const Scene& scene, std::span<const std::int8_t> mesh_sides, std::span<const std::uint8_t> rooms);

}  // namespace ao
