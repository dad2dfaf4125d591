// SPDX-License-Identifier: Apache-2.0
// What each mesh of a scene stands for in the cone method's voxelization (voxelize.h): closed
// (parity), a solid with holes or a sheet, decided from its boundary edges and its generalized
// winding number (Jacobson, Kavan, Sorkine-Hornung, "Robust inside-outside segmentation using
// generalized winding numbers", SIGGRAPH 2013; winding_number.h); and the closed meshes around
// the camera (rooms). Code: mesh_closure.cpp.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "ao/methods/cone/winding_number.h"
#include "ao/scene/mesh.h"

namespace ao {

/// What a mesh stands for, decided per mesh by analyze_closure from its boundary edges and its
/// generalized winding number w (winding_number.h).
enum class MeshKind {
  Closed,          ///< No boundary edge: a solid; parity voxelizes it exactly.
  SolidWithHoles,  ///< Boundary edges, but it wraps around a volume as a closed surface does
                   ///< (MeshClosure::enclosure >= kSolidEnclosure): a scan open at its base, a part
                   ///< with a few holes, an open container (a bowl, a box without its top). It
                   ///< stands for the solid where w > 1/2.
  Sheet,           ///< Any other open mesh (a ground, a wall, sheet metal bent less than a
                   ///< container: an arch): a two-sided surface of no thickness, which the
                   ///< ray-traced reference sees as such.
};

/// Enclosure (MeshClosure::enclosure) from which an open mesh is a solid with holes rather than a
/// sheet: from its surface, the rest of it covers at least half of what the rest of a closed
/// surface covers (the half-space behind the face). Measured: a flat sheet 0, a bent sheet with
/// holes (an arch) 0.34, half a sphere shell 0.63, a box without its top 0.72, a torus with its
/// base cut off 0.74, a sphere with its top tenth cut off 0.91, the shared scans with their bases
/// cut 0.93-0.996 and with holes punched 0.99-1.00 (docs/methods/cone.md, "Open meshes").
inline constexpr float kSolidEnclosure = 0.5f;
/// Triangles sampled (evenly by index) to measure the enclosure of one open mesh.
inline constexpr std::size_t kEnclosureSamples = 256;

/// The winding number field of one mesh (winding_number.h), built on first use (from any thread,
/// once) and shared by copies. Keeps a pointer to the mesh, which must outlive it.
class MeshWinding {
 public:
  MeshWinding() = default;
  explicit MeshWinding(const Mesh& mesh);
  /// The field, in the mesh's own space; an empty field for a default-constructed one.
  const WindingNumber& get() const;

 private:
  struct State;
  std::shared_ptr<State> state_;
};

/// Holes whose areas (each |vector area|, the area it spans seen from its best direction) sum to
/// less than this fraction of the mesh's area make it a solid with holes without measuring its
/// enclosure: holes that small cannot open it (its enclosure is then about 1 minus that fraction).
inline constexpr float kSmallHoles = 0.01f;

/// One mesh's topology and what it stands for, computed once per scene (the scene must not change
/// while it is used).
struct MeshClosure {
  std::size_t boundary_edges = 0;  ///< Edges used by an odd number of triangles (positions compared exactly).
  std::size_t edges = 0;           ///< Distinct edges.
  /// One directed edge (vertex indices, as a triangle lists it) per boundary edge, and the hole
  /// (connected component of boundary edges) it belongs to, numbered from 0.
  std::vector<std::array<std::uint32_t, 2>> boundary;
  std::vector<std::uint32_t> boundary_triangle;  ///< Per boundary edge: the triangle that lists it.
  /// Sheets: per boundary edge, 1 when it is a free rim, one the surface does not go on across (not
  /// a T-junction between pieces of it, not an edge where it folds into another piece); the cone
  /// method's points beyond a free rim see past the sheet (cone_sides.cpp, beyond_rim).
  std::vector<std::uint8_t> free_rim;
  std::vector<std::uint32_t> hole;
  std::uint32_t holes = 0;
  MeshKind kind = MeshKind::Closed;
  /// Open meshes: the magnitude of the area-weighted mean of 2 w_rest over the surface (sampled at
  /// kEnclosureSamples triangles), in [0, 1], where w_rest is the winding number at a point of the
  /// surface of the rest of the mesh (all but the point's own triangle):
  /// 1 for a closed surface (the rest wraps all around), 0 for a flat sheet. 1 for closed meshes;
  /// 1 minus the holes' area fraction for meshes with small holes (kSmallHoles).
  float enclosure = 1;
  /// Open meshes: +1 when the fronts face out of what the mesh wraps around (the sign of w_rest, or
  /// of the enclosed volume for small holes), -1 when they face in (a solid with holes then has
  /// w < -1/2 inside: its w is used negated).
  int orientation = 1;
  /// Open meshes: every vertex within 1e-5 of the extent of one plane (a ground, a wall): then
  /// `plane` (n.x, n.y, n.z, d; n unit along the vector area) has n.p + d < 0 exactly where w > 0.
  bool flat = false;
  std::array<float, 4> plane{};
  /// Open meshes: the winding number field of the mesh in its own space.
  MeshWinding winding;

  bool closed() const { return kind == MeshKind::Closed; }
  /// A sheet (MeshKind::Sheet).
  bool open_surface() const { return kind == MeshKind::Sheet; }
  /// A solid with holes (MeshKind::SolidWithHoles).
  bool holed() const { return kind == MeshKind::SolidWithHoles; }
};

/// The frame of boundary edge a -> b of the triangle (a, b, apex): its unit normal `n` and `out`,
/// the unit direction in its plane across the edge away from the triangle. False for a triangle of
/// no area.
inline bool rim_frame(Vec3 a, Vec3 b, Vec3 apex, Vec3& out, Vec3& n) {
  const Vec3 area = cross(b - a, apex - a);
  if (!(length(area) > 0.0f)) return false;
  n = normalize(area);
  out = normalize(cross(b - a, n));
  if (dot(out, apex - a) > 0.0f) out = -out;
  return true;
}

/// The vertex of boundary edge e's triangle opposite the edge.
inline std::uint32_t rim_apex(const Mesh& m, const MeshClosure& c, std::size_t e) {
  const std::uint32_t* t = m.indices.data() + 3 * static_cast<std::size_t>(c.boundary_triangle[e]);
  const std::uint32_t a = c.boundary[e][0], b = c.boundary[e][1];
  return t[0] != a && t[0] != b ? t[0] : t[1] != a && t[1] != b ? t[1] : t[2];
}

/// Boundary edges of every mesh of `scene`, in mesh order. Vertices are matched by exact position,
/// so meshes whose faces carry their own copies of shared corners (make_box) count as closed.
std::vector<MeshClosure> analyze_closure(const Scene& scene);

/// Which objects of `scene` are closed meshes (closure[mesh].closed()) with `eye` inside them (an
/// odd number of crossings along a ray from it), per Scene::objects(); empty when there are none.
/// Whichever way their faces turn, a closed surface around the viewer is a room.
std::vector<std::uint8_t> closed_meshes_around(const Scene& scene, std::span<const MeshClosure> closure, Vec3 eye);

}  // namespace ao
