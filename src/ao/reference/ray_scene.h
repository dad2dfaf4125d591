// SPDX-License-Identifier: Apache-2.0
// RayScene: a Scene built into a BVH for ray queries. Embree does the work, but no Embree type
// appears here: kernels in reference/, gbuffer/ and bake/ reach the Embree scene through the
// internal header ao/reference/embree_scene_internal.h, which is not part of the installed API.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>

#include "ao/scene/mesh.h"

namespace ao {

/// How hard the BVH builder works (Embree's build qualities).
enum class BvhQuality {
  Low,     ///< Morton-code build: fastest to build, slowest to trace.
  Medium,  ///< Binned SAH build.
  High,    ///< SAH with spatial splits: fastest to trace, slowest to build, most memory.
};

/// Scenes of more triangles than this get a Medium, compact BVH by default; smaller ones a High
/// one. The High build's spatial splits and vertex copies in its leaves take about 100 bytes per
/// triangle; the compact Medium BVH about a third of that, for traces that are slower by the
/// ratio given in BENCHMARKS.md ("Loading big meshes", where the rule is measured).
inline constexpr std::size_t kCompactBvhTriangles = 4'000'000;

/// BVH build settings; every field left empty is chosen from the triangle count (of each BVH: the
/// world-space meshes together, and each instanced mesh on its own).
struct BvhOptions {
  std::optional<BvhQuality> quality;  ///< Empty: High up to kCompactBvhTriangles, Medium above.
  std::optional<bool> compact;        ///< Leaves that index the mesh's vertices instead of copying them. Empty: above kCompactBvhTriangles.
  /// Triangles that share an edge are paired into one quad primitive (a lone triangle is a quad
  /// with its last vertex repeated): the same surfaces in about half the primitives, a smaller
  /// BVH that occlusion rays traverse faster (the ray-traced bake's, bake_bvh_options). A hit's
  /// triangle is then found from the quad and the hit's (u, v) (embree_scene_internal.h's resolve
  /// with u and v). Off: one primitive per triangle. A scene with a mesh of 2^30 triangles or more
  /// stays triangles.
  bool quads = false;
};

class RayScene {
 public:
  /// Builds the BVH for `scene`, which must outlive this object, stay unmodified while it lives,
  /// and have passed validate_and_prepare. Object i of Scene::objects() becomes geometry i (without
  /// instances: mesh i); an instanced mesh gets one BVH of its own, which each of its instances
  /// references through its transform (one BVH over the instances on top, not a copy per
  /// instance). Embree reads the meshes' positions and indices in place (no copy) when the
  /// positions have the spare capacity validate_and_prepare reserves (kVertexPadding); otherwise it
  /// copies them. Throws InputError for a scene smaller than kMinSceneExtent (check_traceable_size),
  /// SystemError when Embree fails.
  explicit RayScene(const Scene& scene, const BvhOptions& options = {});
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  const Scene& scene() const { return source_; }
  const Bounds3& bounds() const { return bounds_; }

  /// Widest ray packet (16, 8, 4 or 1) this Embree build supports natively on this CPU.
  int native_packet_width() const { return packet_width_; }

  /// The build settings used for the top-level BVH, with the automatic choices resolved.
  BvhQuality quality() const { return quality_; }
  bool compact() const { return compact_; }
  /// Whether the BVH's primitives are quads of paired triangles (BvhOptions::quads).
  bool quads() const { return quads_; }

  /// Embree's device and scene; defined in ao/reference/embree_scene_internal.h (internal).
  struct Handles;
  const Handles& handles() const { return *handles_; }

 private:
  const Scene& source_;
  Bounds3 bounds_;
  std::unique_ptr<Handles> handles_;
  int packet_width_ = 1;
  BvhQuality quality_ = BvhQuality::High;
  bool compact_ = false;
  bool quads_ = false;
};

}  // namespace ao
