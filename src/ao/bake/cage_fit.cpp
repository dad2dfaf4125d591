// SPDX-License-Identifier: Apache-2.0
// The default cage distance of a high-to-low bake, chosen from the pair's geometry (high_to_low.h,
// fitted_cage_extrusion). A cage ray through a point p of the low surface finds the high mesh
// when the high surface lies within the cage distance D of p along the ray: outside p (the ray
// starts D out, on the cage) or inside it (the ray goes on D past p, the default --max-back).
// Along p's smoothed normal n that distance is min(t+, t-), the first hit of the high mesh from p
// along +n and along -n. D is the area-weighted 99th percentile of it over four points of every
// low triangle (its centroid and the midpoints between the centroid and each corner), so cage
// rays reach the high mesh from about 99% of the low surface; a point of the low surface with
// no high surface within kCageSearchFraction of the diagonal on either side is left out (a part
// of the low mesh the high meshes do not cover misses at any D).
#include <algorithm>
#include <cmath>
#include <vector>

#include <tbb/parallel_for.h>

#include "ao/bake/high_to_low.h"
#include "ao/reference/embree_scene_internal.h"

namespace ao {

namespace {

constexpr float kCoveredFraction = 0.99f;     // of the low surface's area the cage must reach
constexpr float kCageSearchFraction = 0.25f;  // of the low diagonal: farther high surface is not this point's match
constexpr float kCageMaxFraction = 0.1f;      // of the low diagonal: the largest fitted D

// Distance from o to the first face of `targets` along d, within tfar; infinity when none.
float first_hit(const RayScene& targets, RTCIntersectContext& ctx, Vec3 o, Vec3 d, float tfar) {
  RTCRayHit rh{};
  rh.ray = {o.x, o.y, o.z, 0.0f, d.x, d.y, d.z, 0.0f, tfar, 0xffffffffu, 0, 0};
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(embree_scene(targets), &ctx, &rh);
  return rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? kInfinity : rh.ray.tfar;
}

struct Need {
  float distance;  ///< min(t+, t-) at the point, world units.
  float weight;    ///< A quarter of the triangle's area.
};

}  // namespace

float fitted_cage_extrusion(const Scene& low, const RayScene& targets) {
  const float diagonal = low.bounds().diagonal();
  const float least = kDefaultCageFraction * diagonal, reach = kCageSearchFraction * diagonal;
  const auto normals = smoothed_vertex_normals(low);
  std::vector<std::pair<std::size_t, std::size_t>> triangles;  // (mesh, triangle)
  for (std::size_t mi = 0; mi < low.meshes.size(); ++mi)
    for (std::size_t t = 0; t < low.meshes[mi].triangle_count(); ++t) triangles.emplace_back(mi, t);
  std::vector<Need> needs(4 * triangles.size(), Need{kInfinity, 0.0f});
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, triangles.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (std::size_t k = r.begin(); k < r.end(); ++k) {
      const auto [mi, t] = triangles[k];
      const Mesh& m = low.meshes[mi];
      const std::uint32_t* i = &m.indices[3 * t];
      const Vec3 p[3] = {m.positions[i[0]], m.positions[i[1]], m.positions[i[2]]};
      const Vec3 n[3] = {normals[mi][i[0]], normals[mi][i[1]], normals[mi][i[2]]};
      const float area = 0.5f * length(cross(p[1] - p[0], p[2] - p[0]));
      // Barycentrics of the centroid and of the midpoints between it and each corner.
      constexpr float kBary[4][3] = {{1 / 3.f, 1 / 3.f, 1 / 3.f}, {2 / 3.f, 1 / 6.f, 1 / 6.f}, {1 / 6.f, 2 / 3.f, 1 / 6.f}, {1 / 6.f, 1 / 6.f, 2 / 3.f}};
      for (int j = 0; j < 4; ++j) {
        const Vec3 o = p[0] * kBary[j][0] + p[1] * kBary[j][1] + p[2] * kBary[j][2];
        const Vec3 s = n[0] * kBary[j][0] + n[1] * kBary[j][1] + n[2] * kBary[j][2];
        if (!(length(s) > 0)) continue;
        const Vec3 d = normalize(s);
        const float t_out = first_hit(targets, ctx, o, d, reach), t_in = first_hit(targets, ctx, o, -d, reach);
        needs[4 * k + static_cast<std::size_t>(j)] = {std::min(t_out, t_in), 0.25f * area};
      }
    }
  });
  std::erase_if(needs, [](const Need& n) { return !(n.distance < kInfinity) || !(n.weight > 0); });
  if (needs.empty()) return least;
  std::sort(needs.begin(), needs.end(), [](const Need& a, const Need& b) { return a.distance < b.distance; });
  double total = 0;
  for (const Need& n : needs) total += n.weight;
  double below = 0;
  float quantile = needs.back().distance;
  for (const Need& n : needs)
    if ((below += n.weight) >= kCoveredFraction * total) {
      quantile = n.distance;
      break;
    }
  // Slightly past the quantile, so the point that sets it is reached, not grazed.
  return std::clamp(quantile * 1.05f, least, std::max(least, kCageMaxFraction * diagonal));
}

}  // namespace ao
