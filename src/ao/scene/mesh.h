// SPDX-License-Identifier: Apache-2.0
// Indexed triangle meshes and scenes made of several of them.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ao/core/affine.h"
#include "ao/core/camera.h"
#include "ao/core/math.h"
#include "ao/scene/analytic.h"

namespace ao {

/// Largest coordinate magnitude (world units) a scene may have; validate_and_prepare refuses larger
/// ones. Measured (BENCHMARKS.md, "Input limits"): `ao render` of a cube gives the same image at
/// half-sides 1 to 2e9 and a different, wrong one from 3e9; Embree 3.13's own traversal misses
/// from 1e13 and aborts on an assertion from about 2e18. 1e9 keeps a margin below the first failure.
inline constexpr float kMaxCoordinate = 1e9f;

/// Smallest extent (the longest side of the bounding box, world units) of a scene ao traces
/// correctly: RayScene refuses smaller ones. Measured (docs/assets.md, "Tiny and squashed
/// models"): a hand model renders the same mean V (to 1e-5) at sizes 1e8 down to 1e-7, a visibly
/// wrong one at 1e-8 (0.85 for 0.95) and 1e-9 (0.15); 1e-6 keeps a margin of 10 above the last
/// good size. (Loading accepts smaller meshes: their normals and areas are computed at unit scale.)
inline constexpr float kMinSceneExtent = 1e-6f;

/// Largest squash_ratio (affine.h) of a transform that places a mesh: beyond about 2^23 (8.4e6)
/// the squashed axis is below the float spacing of the others, and from about 1e16 Embree's ray
/// validity check aborts the process (a glTF node scaled 1e-20 along one axis).
inline constexpr double kMaxSquashRatio = 1e7;

/// Why the transform `t` cannot place a mesh ao traces, as the end of a sentence that starts with
/// the node's name ("has a non-finite transform", "has a transform with determinant 0 (it flattens
/// the mesh)", "has a transform that squashes the mesh: it scales one direction 1.4e+20 times more
/// than another, ao traces at most 1e+07"); empty when it can.
std::string transform_problem(const Affine3& t);

/// Spare elements of capacity that validate_and_prepare keeps behind Mesh::positions, so that a ray
/// tracer may share the array and read 16 bytes from the last vertex (Embree's SIMD loads read 4
/// bytes past its end; two Vec3 are 24 bytes).
inline constexpr std::size_t kVertexPadding = 2;

/// One indexed triangle mesh with one material.
struct Mesh {
  std::string name;
  std::vector<Vec3> positions;         ///< World units.
  std::vector<Vec3> normals;           ///< Per vertex, unit; empty until generated or loaded.
  std::vector<Vec2> uvs;               ///< Per vertex, first UV set; empty when the mesh has none.
  std::vector<std::uint32_t> indices;  ///< Three per triangle, counter-clockwise seen from the front.
  Vec3 albedo{0.8f, 0.8f, 0.8f};       ///< Diffuse albedo of the mesh's material, linear RGB in [0,1].

  std::size_t triangle_count() const { return indices.size() / 3; }
  Bounds3 bounds() const;
};

/// One more placement of a mesh in the world: a glTF node that uses a mesh which other nodes use
/// too. The mesh is stored once, in its own (object) space, and traced through the transform.
struct Instance {
  std::uint32_t mesh = 0;   ///< Index into Scene::meshes.
  Affine3 object_to_world;  ///< Finite, invertible (checked by validate_and_prepare).
  std::string name;         ///< The node's name, for messages; may be empty.
};

/// One thing the scene shows, as the G-buffer's object ids count them (object id = index + 1):
/// a mesh drawn once in world space, or one instance of a mesh.
struct SceneObject {
  static constexpr std::uint32_t kNoInstance = 0xffffffffu;
  std::uint32_t mesh = 0;                 ///< Index into Scene::meshes.
  std::uint32_t instance = kNoInstance;   ///< Index into Scene::instances, or kNoInstance (world space).
};

/// A scene: meshes, plus an optional camera the scene was designed to be seen from, and (for
/// built-in scenes that are exactly such surfaces) analytic descriptions of what the meshes show.
///
/// Instances: a mesh that some entry of `instances` names is in object space and is drawn only
/// through its instances (each one its own object); every other mesh is in world space and drawn
/// once. With `instances` empty (built-in scenes, OBJ/PLY/OFF/STL, glTF files that use no mesh
/// twice, or any file loaded with LoadOptions::flatten_instances) every mesh is drawn once.
struct Scene {
  std::string name;                     ///< File name or built-in scene name, used in messages.
  std::vector<Mesh> meshes;
  std::vector<Instance> instances;      ///< Further placements of meshes; see above.
  std::optional<Camera> preferred_view; ///< Eye/target/up/fov only; size comes from the caller.
  AnalyticSurfaces analytic;            ///< World space; empty for scenes from files. The meshes are authoritative, these describe them.
  std::vector<std::string> warnings;    ///< Things fixed while loading (dropped triangles, ...).

  /// World-space bounds of everything drawn (instances through their transforms).
  Bounds3 bounds() const;
  /// Triangles drawn: an instanced mesh counts once per instance.
  std::size_t triangle_count() const;
  /// Triangles held in memory: every mesh once (what the BVHs and memory estimates scale with).
  std::size_t stored_triangle_count() const;
  /// Vertices held in memory (every mesh once).
  std::size_t vertex_count() const;
  /// What is drawn, in object-id order: the meshes no instance names, in mesh order, then the
  /// instances in order. Without instances, object i is mesh i.
  std::vector<SceneObject> objects() const;
};

/// The same scene with every instance copied into a world-space mesh of its own (positions through
/// the transform, normals through its cofactor matrix, renormalised), in object order, so object
/// i of the result is object i of `scene`; `instances` of the result is empty. For consumers that
/// need world-space triangles of every object (and as the reference instanced tracing is tested
/// against). `scene` must have passed validate_and_prepare.
Scene flatten_instances(const Scene& scene);

/// Smooth per-vertex normals, weighting each face normal by its angle at the vertex, for a mesh
/// whose `normals` is empty and whose indices are in range. Vertices used by no triangle get +z.
/// Runs in parallel (oneTBB); the result does not depend on the thread count.
void generate_normals(Mesh& mesh);

/// Checks and repairs a scene in place before it is used; `source` names it in messages.
/// Throws InputError for non-finite coordinates or normals, coordinates beyond +-kMaxCoordinate,
/// non-finite UVs, indices out of range, an index count
/// not divisible by 3, per-vertex arrays of the wrong length, and a scene with no triangle left;
/// and, for instances, a mesh index out of range, a non-finite or non-invertible (zero
/// determinant) transform, or a transform that moves a vertex of its mesh beyond +-kMaxCoordinate
/// (the message names the instance's node). Instances of a mesh that lost all its triangles go
/// with it.
/// Drops degenerate (zero-area) triangles, since real meshes carry a few of them, adds a warning
/// with their count, and generates normals where missing (unit length is restored where loaded
/// normals are not).
void validate_and_prepare(Scene& scene);

/// InputError "<scene>: the scene is X units across, less than the 1e-06 ao traces correctly
/// (scale it up)" when the scene's bounds are smaller than kMinSceneExtent on their longest side.
/// RayScene and the bakers call it; loading does not (a tiny mesh loads and gets its normals).
void check_traceable_size(const Scene& scene);

}  // namespace ao
