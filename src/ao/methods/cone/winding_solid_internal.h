// SPDX-License-Identifier: Apache-2.0
// The winding-number solid of a mesh with holes, for the voxelizer (voxelize.cpp; voxelize.h,
// voxelize_world): parity closes each hole by a fan, and next to a fan that is not flat the solid
// w > 1/2 (Jacobson, Kavan, Sorkine-Hornung, SIGGRAPH 2013) is found by walking the columns from
// the fans' fragments, evaluating w = chi - w_C. Not installed.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <tuple>
#include <vector>

#include <tbb/parallel_for.h>

#include "ao/core/affine.h"
#include "ao/methods/cone/voxel_raster_internal.h"
#include "ao/methods/cone/voxelize.h"

namespace ao::voxel_internal {

// The centroid of each hole's boundary vertices (each boundary edge contributes its two ends), and
// whether the hole is flat to the grid: its boundary within `flat` (world units: two voxels) of the
// plane through the centroid normal to the fan's vector area. Off a flat fan |w_fan| < 1/2
// (voxelize_world), so the parity of the mesh with its fans is its winding-number solid there;
// within two voxels of a plane, the pocket between the fan and the surface w = 1/2 that spans the
// hole lies in a sliver of that thickness along the plane (a scan's base cut through its
// triangles zigzags by a triangle's height), which is left to parity.
// `near` marks the mesh's triangles near the rim of a hole that is not flat: where the pocket
// between that hole's fan and its spanning surface can meet the mesh.
struct Holes {
  std::vector<Vec3> centre;
  std::vector<std::uint8_t> flat;
  std::vector<std::uint8_t> near;  // per triangle
};
Holes hole_centroids(const Mesh& m, const MeshClosure& c, float flat);

// The winding number w_C of one mesh's fans (the triangles (b, a, centroid) over its boundary
// edges a -> b), summed exactly with Van Oosterom and Strackee's formula (winding_number.h): fan
// triangles are slivers from the rim to the centroid, which a hierarchy cannot group. The rim's
// vertices are shared by two edges each, so their offsets and lengths are computed once per point.
struct FanWinding {
  std::vector<Vec3> vertex;                      // rim vertices, then the holes' centroids
  std::vector<std::array<std::uint32_t, 3>> tri;  // (b, a, centroid) into `vertex`
  double operator()(Vec3 q, std::vector<Vec3>& r, std::vector<float>& len) const {
    r.resize(vertex.size());
    len.resize(vertex.size());
    for (std::size_t v = 0; v < vertex.size(); ++v) r[v] = vertex[v] - q, len[v] = length(r[v]);
    double sum = 0;
    for (const auto& [b, a, c] : tri) {
      const float det = dot(r[b], cross(r[a], r[c]));
      if (det == 0.0f) continue;  // q in the triangle's plane: 0 (winding_number.cpp)
      const float den = len[b] * len[a] * len[c] + dot(r[b], r[a]) * len[c] + dot(r[b], r[c]) * len[a] + dot(r[a], r[c]) * len[b];
      sum += std::atan2(det, den);
    }
    return sum * (2.0 / (4.0 * 3.14159265358979323846));
  }
};
FanWinding fan_winding(const Mesh& m, const MeshClosure& c, const Holes& h);

// Object space of an object: the inverse of its instance's map (identity for a world-space mesh),
// and the sign of its determinant (a mirror turns fronts into backs: w changes sign).
struct ObjectSpace {
  bool instanced = false;
  Affine3 to_object;
  int sign = 1;
  Vec3 operator()(Vec3 p) const { return instanced ? to_object.point(p) : p; }
};
inline ObjectSpace object_space(const Scene& scene, const SceneObject& ob) {
  if (ob.instance == SceneObject::kNoInstance) return {};
  const Affine3& m = scene.instances[ob.instance].object_to_world;
  return {true, inverse(m), m.determinant() < 0 ? -1 : 1};
}

// Per slot of a solid with holes (ObjectPlan): object space, sigma (orientation, mirrors
// included) and the winding number of its fans alone (w_C needs no triangle near the point but
// the fans' own, unlike w of the mesh).
struct SlotWinding {
  std::vector<ObjectSpace> space;
  std::vector<int> sign;
  std::vector<FanWinding> fans;
};

// Voxels where w was evaluated, and of those, where it changed the parity's answer; and one
// band's scratch space.
struct WalkCount {
  std::size_t evaluated = 0, changed = 0;
};
struct WalkScratch {
  std::vector<std::uint64_t> chi, seen;
  std::vector<Vec3> r;
  std::vector<float> len;
};

// Walks the column of list[q] from each of its fragments of the same slot (sorted together),
// both ways, setting each voxel to [sigma w(centre) > 1/2] until that agrees with parity (see
// winding_solid). chi is the column as parity left it, so each voxel is decided once however many
// walks reach it. Returns the index past those fragments.
template <class Centre>
std::size_t walk_column(VoxelGrid& g, const std::vector<ColumnHit>& list, std::size_t q, const SlotWinding& sw, Centre& voxel_centre, WalkScratch& sc,
                        WalkCount& n) {
  std::vector<std::uint64_t>& chi = sc.chi;
  std::vector<std::uint64_t>& seen = sc.seen;
  const ColumnHit& at = list[q];
  std::uint64_t* col = g.bits.data() + (static_cast<std::size_t>(at.j) * g.nx + at.i) * g.words;
  chi.assign(col, col + g.words);
  seen.assign(g.words, 0);
  const int s = at.tag;
  for (; q < list.size() && list[q].i == at.i && list[q].j == at.j && list[q].tag == s; ++q)
    for (int dir : {1, -1})
      for (int k = dir > 0 ? list[q].k : list[q].k - 1; k >= 0 && k < g.depth_bits; k += dir) {
        const std::uint64_t bit = std::uint64_t{1} << (k & 63);
        const bool parity = (chi[k >> 6] & bit) != 0;
        bool solid;
        if (seen[k >> 6] & bit) {
          solid = (col[k >> 6] & bit) != 0;
        } else {
          // w = chi - w_C: solid where sigma w = chi - sigma w_C > 1/2.
          solid = (parity ? 1.0 : 0.0) - sw.sign[s] * sw.fans[s](sw.space[s](voxel_centre(at.i, at.j, k)), sc.r, sc.len) > 0.5;
          seen[k >> 6] |= bit;
          ++n.evaluated;
          if (solid != parity) col[k >> 6] ^= bit, ++n.changed;
        }
        if (solid == parity) break;
      }
  return q;
}

// The winding-number solid near holes that are not flat. Parity with the fans is the solid chi
// of the mesh plus its fans C; the mesh's own winding number is w = chi - w_C (w is a sum over
// triangles; sigma w with sigma the orientation, voxelize.h), and the solid is w > 1/2. The two
// differ only where |w_C| >= 1/2, which is next to a fan that is not flat: in the pocket between
// the fan and the surface w = 1/2 that spans the hole, which the mesh itself can also cut near
// the hole's rim. Along a column the pocket is entered through the fan or through the mesh near
// the hole (it is bounded by them and that surface), so from each such fragment (`hits`, per
// band) we walk the column both ways and stop at the first voxel where w agrees with parity: the
// pocket's end. (A column that crossed the spanning surface twice and neither the fan nor the
// mesh would be missed.)
template <class Centre>
WalkCount winding_solid(VoxelGrid& g, std::vector<std::vector<ColumnHit>>& hits, const SlotWinding& sw, Centre& voxel_centre) {
  std::vector<WalkCount> in(hits.size());
  tbb::parallel_for(0, static_cast<int>(hits.size()), [&](int b) {
    std::vector<ColumnHit>& list = hits[b];
    std::sort(list.begin(), list.end(), [](const ColumnHit& x, const ColumnHit& y) { return std::tie(x.j, x.i, x.tag, x.k) < std::tie(y.j, y.i, y.tag, y.k); });
    WalkScratch scratch;
    for (std::size_t q = 0; q < list.size();) q = walk_column(g, list, q, sw, voxel_centre, scratch, in[b]);
  });
  WalkCount n;
  for (const WalkCount& w : in) n.evaluated += w.evaluated, n.changed += w.changed;
  return n;
}

}  // namespace ao::voxel_internal
