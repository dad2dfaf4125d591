// SPDX-License-Identifier: Apache-2.0
// The winding-number solid of a mesh with holes (winding_solid_internal.h): each hole's centroid,
// flatness and the triangles near its rim, and the winding number of the fans that close the
// holes (Jacobson, Kavan, Sorkine-Hornung 2013; voxelize.h, voxelize_world).
#include "ao/methods/cone/winding_solid_internal.h"

#include <algorithm>
#include <cmath>

namespace ao::voxel_internal {

Holes hole_centroids(const Mesh& m, const MeshClosure& c, float flat) {
  Holes h{std::vector<Vec3>(c.holes, Vec3{0, 0, 0}), std::vector<std::uint8_t>(c.holes, 1), std::vector<std::uint8_t>(m.triangle_count(), 0)};
  std::vector<float> n(c.holes, 0.0f);
  for (std::size_t e = 0; e < c.boundary.size(); ++e) {
    h.centre[c.hole[e]] += m.positions[c.boundary[e][0]] + m.positions[c.boundary[e][1]];
    n[c.hole[e]] += 2.0f;
  }
  for (std::uint32_t k = 0; k < c.holes; ++k) h.centre[k] = h.centre[k] * (1.0f / n[k]);
  std::vector<Vec3> area(c.holes, Vec3{0, 0, 0});
  std::vector<Bounds3> box(c.holes);
  for (std::size_t e = 0; e < c.boundary.size(); ++e) {
    const Vec3 o = h.centre[c.hole[e]];
    area[c.hole[e]] += cross(m.positions[c.boundary[e][1]] - o, m.positions[c.boundary[e][0]] - o);
    box[c.hole[e]].extend(m.positions[c.boundary[e][0]]);
  }
  const float extent = m.bounds().diagonal(), tol = flat, pad = 0.01f * extent;
  for (std::size_t e = 0; e < c.boundary.size(); ++e) {
    const std::uint32_t k = c.hole[e];
    const Vec3 nk = normalize(area[k]);
    for (int end = 0; end < 2; ++end)
      if (!(std::abs(dot(nk, m.positions[c.boundary[e][end]] - h.centre[k])) <= tol)) h.flat[k] = 0;
  }
  // Near a hole: within its rim's deviation from its plane (how far the pocket reaches from the
  // rim) plus 1% of the mesh's extent of one of its rim vertices.
  std::vector<float> deviation(c.holes, 0.0f);
  for (std::size_t e = 0; e < c.boundary.size(); ++e) {
    const std::uint32_t k = c.hole[e];
    deviation[k] = std::max(deviation[k], std::abs(dot(normalize(area[k]), m.positions[c.boundary[e][0]] - h.centre[k])));
  }
  for (std::uint32_t k = 0; k < c.holes; ++k) {
    if (h.flat[k]) continue;
    const float reach = deviation[k] + pad;
    const Vec3 lo = box[k].lo - Vec3{reach, reach, reach}, hi = box[k].hi + Vec3{reach, reach, reach};
    for (std::size_t t = 0; t < m.triangle_count(); ++t)
      for (int v = 0; v < 3 && !h.near[t]; ++v) {
        const Vec3 p = m.positions[m.indices[3 * t + v]];
        if (p.x < lo.x || p.y < lo.y || p.z < lo.z || p.x > hi.x || p.y > hi.y || p.z > hi.z) continue;
        for (std::size_t e = 0; e < c.boundary.size() && !h.near[t]; ++e)
          if (c.hole[e] == k && length(p - m.positions[c.boundary[e][0]]) <= reach) h.near[t] = 1;
      }
  }
  return h;
}

FanWinding fan_winding(const Mesh& m, const MeshClosure& c, const Holes& h) {
  FanWinding f;
  std::vector<std::uint32_t> slot(m.positions.size(), ~0u);
  const auto at = [&](std::uint32_t v) {
    if (slot[v] == ~0u) slot[v] = static_cast<std::uint32_t>(f.vertex.size()), f.vertex.push_back(m.positions[v]);
    return slot[v];
  };
  for (std::size_t e = 0; e < c.boundary.size(); ++e) f.tri.push_back({at(c.boundary[e][1]), at(c.boundary[e][0]), 0});
  const std::uint32_t first_centre = static_cast<std::uint32_t>(f.vertex.size());
  f.vertex.insert(f.vertex.end(), h.centre.begin(), h.centre.end());
  for (std::size_t e = 0; e < c.boundary.size(); ++e) f.tri[e][2] = first_centre + c.hole[e];
  return f;
}

}  // namespace ao::voxel_internal
