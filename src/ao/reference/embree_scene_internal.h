// SPDX-License-Identifier: Apache-2.0
// Internal: the Embree objects behind a RayScene, for the ray kernels of reference/, gbuffer/ and
// bake/, and the one place a hit is mapped back to the scene (resolve). Not installed; programs
// using the library never see an Embree type.
#pragma once

#include <cstdint>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include <embree3/rtcore.h>

#include "ao/reference/ray_scene.h"
#include "ao/reference/triangle_pairs_internal.h"
#include "ao/scene/topology.h"

namespace ao {

struct RayScene::Handles {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;                 ///< Top level: geometry i is object i (Scene::objects()).
  std::vector<RTCScene> mesh_scenes;        ///< Per mesh: its own scene when it is instanced, else null.
  std::vector<SceneObject> objects;         ///< rs.scene().objects(), by geometry ID of the top level.
  std::vector<Affine3> normal_to_world;     ///< Per instance: cofactor of its transform (face normals; normalise).
  std::vector<detail::TrianglePairs> pairs; ///< Per mesh: its quads when built with BvhOptions::quads, else empty.
  /// Per mesh: closed_mesh_sides (scene/topology.h), computed on first use (mesh_sides below).
  mutable std::once_flag sides_once;
  mutable std::vector<std::int8_t> sides;
};

/// closed_mesh_sides of rs's scene, computed once per RayScene (from any thread) on first use.
inline std::span<const std::int8_t> mesh_sides(const RayScene& rs) {
  const RayScene::Handles& h = rs.handles();
  std::call_once(h.sides_once, [&] { h.sides = closed_mesh_sides(rs.scene()); });
  return h.sides;
}

namespace detail {
/// An RTCError code in words, for the one-line SystemError a failed Embree call becomes
/// ("embree: building the BVH failed: out of memory (...)") instead of "error 4".
std::string embree_error_text(int code);
}  // namespace detail

/// The committed top-level Embree scene of `rs`: object i (Scene::objects()) is geometry i, a
/// triangle geometry for a mesh drawn in world space, an instance geometry for an instance.
inline RTCScene embree_scene(const RayScene& rs) { return rs.handles().scene; }

/// The object a hit belongs to (its top-level geometry ID): an instance hit has geomID = the
/// triangle geometry inside the instanced scene and instID[0] = the instance's top-level ID.
inline unsigned hit_object(unsigned geom_id, unsigned inst_id) { return inst_id != RTC_INVALID_GEOMETRY_ID ? inst_id : geom_id; }

/// What a hit is on: the mesh and its triangle, and the transform from the mesh's coordinates to
/// the world (null: the mesh is in world space).
struct HitRef {
  std::uint32_t object;              ///< Index into Scene::objects() (object id - 1).
  std::uint32_t mesh;                ///< Index into Scene::meshes.
  std::uint32_t triangle;            ///< Triangle within that mesh (Embree's primID).
  const Affine3* to_world = nullptr; ///< Instance transform, or null.
  const Affine3* normal_to_world = nullptr;  ///< Its cofactor matrix (face and vertex normals; normalise), or null.
};

/// Maps a hit (geomID, instID[0], primID; geomID valid) to the scene, in a scene of triangles
/// (built without BvhOptions::quads; the overload below takes any). Every kernel that needs more
/// than "hit or not" and the distance goes through one of the two.
inline HitRef resolve(const RayScene& rs, unsigned geom_id, unsigned inst_id, unsigned prim_id) {
  const RayScene::Handles& h = rs.handles();
  HitRef r;
  r.object = hit_object(geom_id, inst_id);
  const SceneObject& o = h.objects[r.object];
  r.mesh = o.mesh;
  r.triangle = prim_id;
  if (o.instance != SceneObject::kNoInstance) {
    r.to_world = &rs.scene().instances[o.instance].object_to_world;
    r.normal_to_world = &h.normal_to_world[o.instance];
  }
  return r;
}

/// Maps a hit (geomID, instID[0], primID and Embree's hit coordinates u, v) to the scene, whether
/// its primitives are triangles or quads (BvhOptions::quads: the quad's half that (u, v) lies in).
inline HitRef resolve(const RayScene& rs, unsigned geom_id, unsigned inst_id, unsigned prim_id, float u, float v) {
  HitRef r = resolve(rs, geom_id, inst_id, prim_id);
  if (rs.quads()) r.triangle = detail::quad_hit_triangle(rs.handles().pairs[r.mesh], prim_id, u, v);
  return r;
}

/// The world-space vertices of a resolved hit's triangle.
inline void world_triangle(const RayScene& rs, const HitRef& h, Vec3& p0, Vec3& p1, Vec3& p2) {
  const Mesh& m = rs.scene().meshes[h.mesh];
  const std::uint32_t* i = &m.indices[3 * static_cast<std::size_t>(h.triangle)];
  p0 = m.positions[i[0]], p1 = m.positions[i[1]], p2 = m.positions[i[2]];
  if (h.to_world) p0 = h.to_world->point(p0), p1 = h.to_world->point(p1), p2 = h.to_world->point(p2);
}

}  // namespace ao
