// Indexed triangle meshes and scenes made of several of them.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ao/core/camera.h"
#include "ao/core/math.h"
#include "ao/scene/analytic.h"

namespace ao {

/// Largest coordinate magnitude (world units) a scene may have; validate_and_prepare refuses larger
/// ones. Measured (BENCHMARKS.md, "Input limits"): `ao render` of a cube gives the same image at
/// half-sides 1 to 2e9 and a different, wrong one from 3e9; Embree 3.13's own traversal misses
/// from 1e13 and aborts on an assertion from about 2e18. 1e9 keeps a margin below the first failure.
inline constexpr float kMaxCoordinate = 1e9f;

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

/// A scene: meshes, plus an optional camera the scene was designed to be seen from, and (for
/// built-in scenes that are exactly such surfaces) analytic descriptions of what the meshes show.
struct Scene {
  std::string name;                     ///< File name or built-in scene name, used in messages.
  std::vector<Mesh> meshes;
  std::optional<Camera> preferred_view; ///< Eye/target/up/fov only; size comes from the caller.
  AnalyticSurfaces analytic;            ///< World space; empty for scenes from files. The meshes are authoritative, these describe them.
  std::vector<std::string> warnings;    ///< Things fixed while loading (dropped triangles, ...).

  Bounds3 bounds() const;
  std::size_t triangle_count() const;
  std::size_t vertex_count() const;
};

/// Smooth per-vertex normals, weighting each face normal by its angle at the vertex, for a mesh
/// whose `normals` is empty and whose indices are in range. Vertices used by no triangle get +z.
/// Runs in parallel (oneTBB); the result does not depend on the thread count.
void generate_normals(Mesh& mesh);

/// Checks and repairs a scene in place before it is used; `source` names it in messages.
/// Throws InputError for non-finite coordinates or normals, coordinates beyond +-kMaxCoordinate,
/// non-finite UVs, indices out of range, an index count
/// not divisible by 3, per-vertex arrays of the wrong length, and a scene with no triangle left.
/// Drops degenerate (zero-area) triangles, since real meshes carry a few of them, adds a warning
/// with their count, and generates normals where missing (unit length is restored where loaded
/// normals are not).
void validate_and_prepare(Scene& scene);

}  // namespace ao
