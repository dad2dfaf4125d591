// SPDX-License-Identifier: Apache-2.0
// Pairing triangles into Embree quads (BvhOptions::quads): every triangle lands in exactly one
// quad half with its own vertices in its own winding, on meshes with seams, lone triangles,
// non-manifold edges and flipped neighbours; and a quad BVH answers rays as the triangle BVH does.
#include "ao/reference/triangle_pairs_internal.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include "ao/reference/embree_scene_internal.h"
#include "ao/reference/ray_scene.h"
#include "ao/scene/procedural.h"

namespace ao {
namespace {

using detail::pair_triangles;
using detail::TrianglePairs;

// The positions of a quad's half h ((v0, v1, v3) or (v2, v3, v1), as Embree splits it).
std::array<Vec3, 3> half(const Mesh& m, const TrianglePairs& p, std::size_t q, int h) {
  const std::uint32_t* v = &p.quads[4 * q];
  return h == 0 ? std::array<Vec3, 3>{m.positions[v[0]], m.positions[v[1]], m.positions[v[3]]}
                : std::array<Vec3, 3>{m.positions[v[2]], m.positions[v[3]], m.positions[v[1]]};
}

bool same(Vec3 a, Vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

// Checks that the quads hold each triangle of `m` once, as a half equal to it up to rotation
// (same winding); returns the number of lone triangles.
int check_pairs(const Mesh& m, const TrianglePairs& p) {
  const std::size_t nt = m.triangle_count();
  EXPECT_EQ(p.triangles.size(), 2 * p.quad_count());
  std::vector<int> seen(nt, 0);
  int lone = 0;
  for (std::size_t q = 0; q < p.quad_count(); ++q) {
    const bool single = p.triangles[2 * q] == p.triangles[2 * q + 1];
    if (single) {
      ++lone;
      EXPECT_EQ(p.quads[4 * q + 2], p.quads[4 * q + 3]) << "a lone triangle repeats its last vertex";
    }
    for (int h = 0; h < (single ? 1 : 2); ++h) {
      const std::uint32_t t = p.triangles[2 * q + static_cast<std::size_t>(h)];
      ++seen[t];
      const std::array<Vec3, 3> got = half(m, p, q, h);
      const std::array<Vec3, 3> want = {m.positions[m.indices[3 * t]], m.positions[m.indices[3 * t + 1]], m.positions[m.indices[3 * t + 2]]};
      bool rotation = false;
      for (int r = 0; r < 3; ++r) rotation |= same(got[0], want[static_cast<std::size_t>(r)]) && same(got[1], want[static_cast<std::size_t>((r + 1) % 3)]) &&
                                              same(got[2], want[static_cast<std::size_t>((r + 2) % 3)]);
      EXPECT_TRUE(rotation) << "quad " << q << " half " << h << " is not triangle " << t;
    }
  }
  for (std::size_t t = 0; t < nt; ++t) EXPECT_EQ(seen[t], 1) << "triangle " << t;
  EXPECT_EQ(p.paired_triangles, nt - static_cast<std::size_t>(lone));
  return lone;
}

// An n x n grid of squares in z = 0, two triangles each; with split_rows, each row of squares
// has vertices of its own (as a UV seam splits them), at the same positions.
Mesh grid(int n, bool split_rows) {
  Mesh m;
  const auto vertex = [&](int x, int y) {
    m.positions.push_back({static_cast<float>(x), static_cast<float>(y), 0.0f});
    return static_cast<std::uint32_t>(m.positions.size() - 1);
  };
  std::vector<std::uint32_t> id((n + 1) * (n + 1));
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) id[static_cast<std::size_t>(y * (n + 1) + x)] = vertex(x, y);
  for (int y = 0; y < n; ++y) {
    std::uint32_t a[2][2];  // this row's corners
    for (int x = 0; x < n; ++x) {
      for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) a[j][i] = split_rows ? vertex(x + i, y + j) : id[static_cast<std::size_t>((y + j) * (n + 1) + x + i)];
      m.indices.insert(m.indices.end(), {a[0][0], a[0][1], a[1][1], a[0][0], a[1][1], a[1][0]});
    }
  }
  return m;
}

TEST(TrianglePairs, GridPairsEveryTriangle) {
  const Mesh m = grid(6, false);
  const TrianglePairs p = pair_triangles(m);
  EXPECT_EQ(check_pairs(m, p), 0);
  EXPECT_EQ(p.quad_count(), m.triangle_count() / 2);
}

TEST(TrianglePairs, SplitVerticesPairByPosition) {
  // Every square's two triangles pair across their diagonal, even though no two squares share a
  // vertex index and every vertex is split; the halves keep their own indices.
  const Mesh m = grid(5, true);
  const TrianglePairs p = pair_triangles(m);
  EXPECT_EQ(check_pairs(m, p), 0);
}

TEST(TrianglePairs, LoneFlippedAndNonManifoldTriangles) {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {5, 5, 5}, {6, 5, 5}, {5, 6, 5}, {1, 1, 0}};
  m.indices = {
      0, 1, 2,  // three triangles on edge 0-1 (non-manifold): two run it 1 -> 0
      1, 0, 3,  //
      1, 0, 4,  //
      5, 6, 7,  // alone
      1, 8, 2,  // shares 1-2 with the first, which runs it 1 -> 2 too: wound the other way, not paired
      2, 2, 0,  // collapsed
  };
  const TrianglePairs p = pair_triangles(m);
  // Triangle 0 pairs with one of 1 and 2; the other, 3, 4 and 5 stay alone.
  EXPECT_EQ(check_pairs(m, p), 4);
  EXPECT_EQ(p.quad_count(), 5u);
  // An empty mesh has no quads.
  EXPECT_EQ(pair_triangles(Mesh{}).quad_count(), 0u);
}

// A "book" of 20,000 pages on one edge (each page a triangle 0 -> 1 -> its own corner, every
// other one wound the other way): the edge offers no pairs (a fan of more than 8), so every page
// stays alone and pairing stays linear in the page count instead of building 10^8 candidates.
TEST(TrianglePairs, AFanOfManyTrianglesOnOneEdgeStaysAlone) {
  Mesh m;
  m.positions = {{0, 0, 0}, {0, 0, 1}};
  constexpr int kPages = 20000;
  for (int i = 0; i < kPages; ++i) {
    const float a = 6.2831853f * static_cast<float>(i) / kPages;
    m.positions.push_back({std::cos(a), std::sin(a), 0.5f});
    const auto c = static_cast<std::uint32_t>(i + 2);
    m.indices.insert(m.indices.end(), i % 2 ? std::initializer_list<std::uint32_t>{1, 0, c} : std::initializer_list<std::uint32_t>{0, 1, c});
  }
  const TrianglePairs p = pair_triangles(m);
  EXPECT_EQ(check_pairs(m, p), kPages);
}

// Closest hits of random rays through the quad BVH and the triangle BVH of `s`: the same distance
// and (resolve with u, v) the same triangle, but for rays that land on an edge two triangles share.
void expect_same_hits(const Scene& s) {
  const RayScene tris(s, {BvhQuality::Medium, false, false});
  const RayScene quads(s, {BvhQuality::Medium, false, true});
  ASSERT_TRUE(quads.quads());
  ASSERT_FALSE(tris.quads());
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
  const Bounds3 b = s.bounds();
  const Vec3 c = (b.lo + b.hi) * 0.5f;
  const float r = b.diagonal();
  int hits = 0, occluded_agree = 0, differ = 0;
  constexpr int kRays = 4000;
  for (int i = 0; i < kRays; ++i) {
    const Vec3 o = c + Vec3{uni(rng), uni(rng), uni(rng)} * r;
    const Vec3 target = c + Vec3{uni(rng), uni(rng), uni(rng)} * (0.3f * r);
    const Vec3 d = normalize(target - o);
    RTCRayHit h[2];
    const RayScene* rs[2] = {&tris, &quads};
    for (int k = 0; k < 2; ++k) {
      h[k] = {};
      h[k].ray = {o.x, o.y, o.z, 0.0f, d.x, d.y, d.z, 0.0f, kInfinity, 0xffffffffu, 0, 0};
      h[k].hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(embree_scene(*rs[k]), &ctx, &h[k]);
    }
    ASSERT_EQ(h[0].hit.geomID == RTC_INVALID_GEOMETRY_ID, h[1].hit.geomID == RTC_INVALID_GEOMETRY_ID) << "ray " << i;
    RTCRay occ[2];
    for (int k = 0; k < 2; ++k) {
      occ[k] = {o.x, o.y, o.z, 0.0f, d.x, d.y, d.z, 0.0f, kInfinity, 0xffffffffu, 0, 0};
      rtcOccluded1(embree_scene(*rs[k]), &ctx, &occ[k]);
    }
    occluded_agree += (occ[0].tfar < 0) == (occ[1].tfar < 0);
    if (h[0].hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
    ++hits;
    EXPECT_NEAR(h[1].ray.tfar, h[0].ray.tfar, 1e-5f * h[0].ray.tfar) << "ray " << i;
    const HitRef want = resolve(tris, h[0].hit.geomID, h[0].hit.instID[0], h[0].hit.primID);
    const HitRef got = resolve(quads, h[1].hit.geomID, h[1].hit.instID[0], h[1].hit.primID, h[1].hit.u, h[1].hit.v);
    if (got.object != want.object || got.triangle != want.triangle) {
      // Only where the ray meets both triangles at that distance: on an edge they share, or where
      // two objects' faces overlap (the default scene's boxes stand on its floor).
      const Vec3 p = o + d * h[1].ray.tfar;
      Vec3 t0, t1, t2;
      world_triangle(quads, got, t0, t1, t2);
      const Vec3 n = cross(t1 - t0, t2 - t0);
      const float area2 = dot(n, n);
      const float w0 = dot(cross(t2 - t1, p - t1), n) / area2, w1 = dot(cross(t0 - t2, p - t2), n) / area2, w2 = 1.0f - w0 - w1;
      EXPECT_LT(std::abs(dot(p - t0, n)) / std::sqrt(area2), 1e-5f * r) << "ray " << i << ": off the plane of the triangle it hit";
      EXPECT_GT(std::min({w0, w1, w2}), -1e-4f) << "ray " << i << ": object " << got.object << " triangle " << got.triangle << " instead of "
                                                << want.object << " triangle " << want.triangle;
      ++differ;
    }
  }
  EXPECT_EQ(occluded_agree, kRays);
  EXPECT_LT(differ, kRays / 200);  // ties are rare
  EXPECT_GT(hits, kRays / 10);  // enough rays meet the scene to test
}

TEST(TrianglePairs, QuadBvhHitsWhatTheTriangleBvhHits) {
  expect_same_hits(make_builtin_scene("default"));
  Scene spheres;
  spheres.meshes.push_back(make_sphere({0, 0, 0}, 1.0f, 24, 12));  // poles: fans of triangles
  spheres.meshes.push_back(make_torus({0, 2.5f, 0}, 1.0f, 0.3f, 20, 9));  // odd count of sides
  spheres.meshes.push_back(grid(5, true));
  validate_and_prepare(spheres);
  expect_same_hits(spheres);
}

}  // namespace
}  // namespace ao
