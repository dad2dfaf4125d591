// SPDX-License-Identifier: Apache-2.0
// The texel bakers against configurations with known answers (unlimited distance, the paper's
// eq. 1), against each other, and their properties. Scenes are tiny procedural meshes with UVs
// built here, at small map sizes, so the whole file runs in a few seconds.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <set>

#include <tbb/global_control.h>

#include "ao/bake/denoise.h"
#include "ao/bake/high_to_low.h"
#include "ao/bake/histogram.h"
#include "ao/bake/padding.h"
#include "ao/bake/per_vertex.h"
#include "ao/bake/raytraced_bake.h"
#include "ao/bake/texel_coverage.h"
#include "ao/bake/texel_rays_internal.h"
#include "ao/core/error.h"
#include "ao/jobs/bake.h"
#include "ao/scene/procedural.h"
#include "ao/simd/sampling_internal.h"

namespace ao {
namespace {

// Quad with UVs: p0..p3 counter-clockwise seen from the front, p0 -> uv lo, p2 -> uv hi.
Mesh uv_quad(Vec3 p0, Vec3 p1, Vec3 p2, Vec3 p3, Vec2 lo, Vec2 hi) {
  Mesh m = make_quad(p0, p1, p2, p3);
  m.uvs = {{lo.x, lo.y}, {hi.x, lo.y}, {hi.x, hi.y}, {lo.x, hi.y}};
  return m;
}

Scene prepared(Scene s) {
  s.name = "test";
  validate_and_prepare(s);
  return s;
}

// Floor x in [-0.5, 0.5], z in [0, 1] (y = 0, facing up), UVs over the whole map (u = x + 0.5,
// v = z, so image row 0 is the far edge z = 1), next to a wall z = 0 of height H and width
// 2 x half_width (40 by default: as good as infinite for the view factor below) facing +z (a slab
// without UVs: it only occludes).
Scene floor_and_wall(float height, bool stretched = false, float half_width = 20.0f) {
  Scene s;
  if (!stretched) {
    s.meshes.push_back(uv_quad({-0.5f, 0, 1}, {0.5f, 0, 1}, {0.5f, 0, 0}, {-0.5f, 0, 0}, {0, 1}, {1, 0}));
  } else {
    // Same floor as two strips with different v scale: z in [0, 0.5] -> v in [0, 0.75] and
    // z in [0.5, 1] -> v in [0.75, 1], so the far strip's texels cover 3 times more surface.
    Mesh a = uv_quad({-0.5f, 0, 0.5f}, {0.5f, 0, 0.5f}, {0.5f, 0, 0}, {-0.5f, 0, 0}, {0, 0.75f}, {1, 0});
    Mesh b = uv_quad({-0.5f, 0, 1}, {0.5f, 0, 1}, {0.5f, 0, 0.5f}, {-0.5f, 0, 0.5f}, {0, 1}, {1, 0.75f});
    append_mesh(a, b);
    s.meshes.push_back(a);
  }
  // A closed slab, not a single-sided quad: the histogram baker culls back faces (the paper asks
  // for closed meshes), so a lone quad would not occlude light arriving from behind it.
  s.meshes.push_back(make_box({-half_width, 0, -0.2f}, {half_width, height, 0}));
  return prepared(std::move(s));
}

// View factor of a 2-D (infinitely wide) wall of height H from a floor point at distance d: the
// wall spans angles from the normal between atan(d/H) and 90 degrees, and a strip between angles
// t1 < t2 has projected solid angle fraction (sin t2 - sin t1)/2. V = 1 - F.
double wall_visibility(double d, double h) { return 1.0 - (1.0 - d / std::sqrt(d * d + h * h)) / 2.0; }

// Mean of the map over covered texels whose centre is at floor distance in [d0, d1).
double mean_band(const BakeResult& r, int n, double d0, double d1) {
  double s = 0;
  int c = 0;
  for (int y = 0; y < n; ++y) {
    const double d = 1.0 - (y + 0.5) / n;  // row 0 is z = 1
    if (d < d0 || d >= d1) continue;
    for (int x = 0; x < n; ++x)
      if (r.mask(x, y)) {
        s += r.visibility(x, y);
        ++c;
      }
  }
  return c ? s / c : -1.0;
}

TEST(Bake, SingleQuadIsFullyVisibleBothMethods) {
  Scene s;
  s.meshes.push_back(uv_quad({-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}, {0, 0}, {1, 1}));
  s = prepared(std::move(s));
  const TexelCoverage cov = compute_texel_coverage(s, 16);
  EXPECT_EQ(cov.covered_texels, 256u);
  const BakeResult h = bake_histogram(s, cov, {.directions = 256, .pixels_per_texel = 2.0f});
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  const BakeResult r = bake_raytraced(rs, cov, {.samples = 64});
  double hmin = 1, hsum = 0;
  for (std::size_t i = 0; i < h.visibility.size(); ++i) {
    hmin = std::min<double>(hmin, h.visibility[i]);
    hsum += h.visibility[i];
    EXPECT_EQ(r.visibility[i], 1.0f) << "raytraced texel " << i;
  }
  // Histogram: each texel's value is a pixel count over its projected area, unbiased with the
  // jittered grids; at 256 directions and 2x2 pixels per texel a texel is off by ~3% (std. dev.),
  // and clamping V to 1 biases the mean down by about 0.4 of that.
  EXPECT_NEAR(hsum / 256.0, 1.0, 0.02);
  EXPECT_GT(hmin, 0.85);
}

// A chart that grazes a column of texels with a sliver (1% of a texel wide): no pixel sample lands
// in those texels, and 0 samples over the area must not read as V = 0 (the dragon's dark dots).
// They copy the nearest texel that has enough samples; on an open quad that is V ~ 1.
TEST(Bake, SliverTexelsOnChartBordersAreNotBlack) {
  Scene s;
  const float eps = 0.01f / 16;
  s.meshes.push_back(uv_quad({-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}, {0.25f - eps, 0.25f}, {0.75f, 0.75f}));
  s = prepared(std::move(s));
  const TexelCoverage cov = compute_texel_coverage(s, 16);
  for (bool seam_fix : {true, false}) {
    const BakeResult h = bake_histogram(s, cov, {.directions = 128, .pixels_per_texel = 2.0f, .seam_fix = seam_fix});
    int slivers = 0;
    for (int y = 0; y < 16; ++y)
      if (cov.mask(3, y)) {
        ++slivers;
        EXPECT_GT(h.visibility(3, y), 0.8f) << "sliver texel row " << y << (seam_fix ? "" : " (no seam fix)");
      }
    EXPECT_EQ(slivers, 8);
    EXPECT_EQ(h.stats["unreliable_texels"], 8);
    EXPECT_EQ(h.stats["unreliable_texels_unfilled"], 0);
  }
  // With the check off, they are the raw estimate: no sample, V = 0.
  const BakeResult raw = bake_histogram(s, cov, {.directions = 128, .pixels_per_texel = 2.0f, .seam_fix = false, .min_samples = 0.0f});
  EXPECT_EQ(raw.visibility(3, 5), 0.0f);
}

TEST(Bake, FloorNextToWallMatchesViewFactorBothMethods) {
  const Scene s = floor_and_wall(1.0f);
  const int n = 16;
  const TexelCoverage cov = compute_texel_coverage(s, n);
  const BakeResult h = bake_histogram(s, cov, {.directions = 1024, .pixels_per_texel = 2.0f});
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  const BakeResult r = bake_raytraced(rs, cov, {.samples = 1024});
  for (int band = 0; band < 4; ++band) {
    const double d0 = band * 0.25, d1 = d0 + 0.25;
    // Band mean of the analytic V (texel averages over the band) by the midpoint rule on 64 points.
    double truth = 0;
    for (int k = 0; k < 64; ++k) truth += wall_visibility(d0 + (k + 0.5) / 64 * 0.25, 1.0) / 64;
    // Tolerances: raytraced band mean has 64 texels x 1024 rays, std. error < 0.002; the
    // histogram's band mean over 64 texels at 1024 directions is within ~0.01 (measured spread
    // over seeds 0.004); the finite wall (40 wide) changes V by < 1e-3.
    EXPECT_NEAR(mean_band(r, n, d0, d1), truth, 0.008) << "raytraced band " << band;
    EXPECT_NEAR(mean_band(h, n, d0, d1), truth, 0.02) << "histogram band " << band;
  }
}

// A low wall (h = 0.1) beside an 8 x 8 floor map: V(d) = 1/2 + d / (2 sqrt(d^2 + h^2)) bends
// within a texel (1/8) of the wall. texel_sampling area holds each texel's mean over its strip of
// floor, (sqrt(d1^2 + h^2) - sqrt(d0^2 + h^2)) / (2 (d1 - d0)) + 1/2; centre holds V at the
// texel's centre, as Cycles bakes: in the row at the wall 0.740 against 0.765. 4096 rays per
// texel, 8 texels a row: each row's mean within 0.004 of its own quantity (the rows' standard
// errors are below 0.001).
TEST(Bake, CentreSamplingPointSamplesWhereAreaSamplingAverages) {
  const double h = 0.1;
  const Scene s = floor_and_wall(static_cast<float>(h));
  const int n = 8;
  const TexelCoverage cov = compute_texel_coverage(s, n);
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  const BakeResult area = bake_raytraced(rs, cov, {.samples = 4096});
  const BakeResult centre = bake_raytraced(rs, cov, {.samples = 4096, .texel_sampling = TexelSampling::Centre});
  auto row_mean = [&](const BakeResult& r, int y) {
    double m = 0;
    for (int x = 0; x < n; ++x) m += r.visibility(x, y) / n;
    return m;
  };
  for (int y = 0; y < n; ++y) {
    const double d0 = 1.0 - (y + 1.0) / n, d1 = 1.0 - static_cast<double>(y) / n, dc = 0.5 * (d0 + d1);  // row 0 is z = 1
    const double mean = 0.5 + (std::sqrt(d1 * d1 + h * h) - std::sqrt(d0 * d0 + h * h)) / (2 * (d1 - d0));
    EXPECT_NEAR(row_mean(area, y), mean, 0.004) << "area, row " << y;
    EXPECT_NEAR(row_mean(centre, y), wall_visibility(dc, h), 0.004) << "centre, row " << y;
  }
  EXPECT_GT(row_mean(centre, n - 1) - row_mean(area, n - 1), 0.02);  // the row at the wall tells them apart
}

// Centre sampling is for single-mesh maps: a vertex has no texel, and high to low casts from the
// cage's patch; the histogram baker has no such setting. Each refused before anything is loaded.
TEST(Bake, CentreSamplingIsRefusedWhereThereIsNoTexelCentre) {
  auto refused = [](BakeRequest r, const std::string& says) {
    r.inputs = {"mesh.obj"};
    r.raytraced.texel_sampling = TexelSampling::Centre;
    try {
      resolve_bake_request(r);
      ADD_FAILURE() << "accepted; expected: " << says;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  };
  BakeRequest vertex;
  vertex.outputs.per_vertex = "v.ply";
  refused(vertex, "a vertex has no texel");
  BakeRequest high;
  high.high = {"high.obj"};
  refused(high, "high to low");
  BakeRequest histogram;
  histogram.method = Baker::Histogram;
  refused(histogram, "histogram");
  HighToLowParams h2l;
  h2l.ao.texel_sampling = TexelSampling::Centre;
  EXPECT_THROW(h2l.validate(), InputError);
}

// A W x H map: texel (x, y) covers u in [x/W, (x+1)/W], v in [1 - (y+1)/H, 1 - y/H]. A quad on
// u in [0, 0.5], v in [0.5, 1] covers exactly the top-left quarter of a 32 x 8 map, each texel
// fully, and the world areas add up to the quad's (2 x 2 = 4).
TEST(Bake, NonSquareCoverageFollowsTheTexelGrid) {
  Scene s;
  s.meshes.push_back(uv_quad({-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}, {0, 0.5f}, {0.5f, 1}));
  s = prepared(std::move(s));
  const TexelCoverage cov = compute_texel_coverage(s, 32, 8);
  ASSERT_EQ(cov.mask.width(), 32);
  ASSERT_EQ(cov.mask.height(), 8);
  EXPECT_EQ(cov.covered_texels, 16u * 4u);
  double world = 0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 32; ++x) {
      EXPECT_EQ(cov.mask(x, y), x < 16 && y < 4 ? 1 : 0) << x << "," << y;
      if (cov.mask(x, y)) {
        EXPECT_NEAR(cov.uv_area(x, y), 1.0f, 1e-4f) << x << "," << y;
      }
      world += cov.world_area(x, y);
    }
  EXPECT_NEAR(world, 4.0, 1e-4);
  EXPECT_THROW(compute_texel_coverage(s, 32, 0), InputError);
  EXPECT_THROW(compute_texel_coverage(s, 16385, 8), InputError);
}

// The floor-and-wall known answer on a tall, narrow map (6 x 24): the rows still run from the far
// edge to the wall, so the band means follow the same view factor as on a square map.
TEST(Bake, NonSquareMapMatchesViewFactorBothMethods) {
  const Scene s = floor_and_wall(1.0f);
  const int w = 6, h = 24;
  const TexelCoverage cov = compute_texel_coverage(s, w, h);
  EXPECT_EQ(cov.covered_texels, static_cast<std::size_t>(w * h));
  const BakeResult hist = bake_histogram(s, cov, {.directions = 1024, .pixels_per_texel = 2.0f});
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  const BakeResult ray = bake_raytraced(rs, cov, {.samples = 1024});
  for (const BakeResult* r : {&hist, &ray}) {
    ASSERT_EQ(r->visibility.width(), w);
    ASSERT_EQ(r->visibility.height(), h);
  }
  auto band_mean = [&](const BakeResult& r, double d0, double d1) {
    double sum = 0;
    int c = 0;
    for (int y = 0; y < h; ++y) {
      const double d = 1.0 - (y + 0.5) / h;  // row 0 is z = 1
      if (d < d0 || d >= d1) continue;
      for (int x = 0; x < w; ++x) {
        sum += r.visibility(x, y);
        ++c;
      }
    }
    return sum / c;
  };
  for (int band = 0; band < 4; ++band) {
    const double d0 = band * 0.25, d1 = d0 + 0.25;
    double truth = 0;
    for (int k = 0; k < 64; ++k) truth += wall_visibility(d0 + (k + 0.5) / 64 * 0.25, 1.0) / 64;
    // 36 texels per band (6 rows of 6): raytraced std. error < 0.003 at 1024 rays; the histogram
    // tolerance is the square test's (0.02), its noise per texel being the same.
    EXPECT_NEAR(band_mean(ray, d0, d1), truth, 0.01) << "raytraced band " << band;
    EXPECT_NEAR(band_mean(hist, d0, d1), truth, 0.02) << "histogram band " << band;
  }
}

// Inside a closed box, seen from outside (unlimited distance): nothing reaches the floor quad.
TEST(Bake, QuadInsideClosedBoxIsFullyOccluded) {
  Scene s;
  s.meshes.push_back(uv_quad({-0.5f, 0.1f, 0.5f}, {0.5f, 0.1f, 0.5f}, {0.5f, 0.1f, -0.5f}, {-0.5f, 0.1f, -0.5f}, {0, 0}, {1, 1}));
  s.meshes.push_back(make_box({-1, 0, -1}, {1, 1, 1}));
  s = prepared(std::move(s));
  const TexelCoverage cov = compute_texel_coverage(s, 8);
  const BakeResult h = bake_histogram(s, cov, {.directions = 128});
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  const BakeResult r = bake_raytraced(rs, cov, {.samples = 64});
  for (std::size_t i = 0; i < h.visibility.size(); ++i) {
    EXPECT_EQ(h.visibility[i], 0.0f);
    EXPECT_EQ(r.visibility[i], 0.0f);
  }
  // Ignoring back faces, the rays leave through the box's inner (back) faces: fully open.
  const BakeResult rb = bake_raytraced(rs, cov, {.samples = 64, .ignore_back_faces = true});
  for (std::size_t i = 0; i < rb.visibility.size(); ++i) EXPECT_EQ(rb.visibility[i], 1.0f);
}

TEST(Bake, TileLoopVisitsEveryCoveredTexelOnceWithItsOwnFragments) {
  // Maps whose sides are not multiples of the tile (16) nor of the coverage's bins (8), on several
  // threads: each covered texel gets exactly one call, with the fragments texel_fragments gives it
  // (a tile that ran past its own texels into a neighbour's bin would visit some twice).
  Scene s;
  s.meshes.push_back(uv_quad({-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}, {0.02f, 0.03f}, {0.97f, 0.99f}));
  s = prepared(std::move(s));
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  const detail::TriangleNormals fn = detail::face_normals(s);
  const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 3);
  for (const auto& [w, h] : {std::pair{37, 23}, std::pair{100, 61}, std::pair{8, 9}}) {
    const TexelCoverage cov = compute_texel_coverage(s, w, h);
    std::vector<std::atomic<int>> visits(cov.texel_count());
    std::atomic<int> wrong_fragments{0};
    struct Worker {
      const Scene& scene;
      const TexelCoverage& cov;
      std::vector<std::atomic<int>>& visits;
      std::atomic<int>& wrong;
      std::vector<TexelPiece> alone;
      void operator()(RTCIntersectContext&, int x, int y, std::size_t texel, const std::vector<detail::PatchPiece>&, std::span<const TexelPiece> fr) {
        ++visits[texel];
        texel_fragments(scene, cov, texel, alone);
        const bool same = texel == static_cast<std::size_t>(y) * static_cast<std::size_t>(cov.width) + static_cast<std::size_t>(x) &&
                          fr.size() == alone.size() &&
                          std::equal(fr.begin(), fr.end(), alone.begin(), [](const TexelPiece& a, const TexelPiece& b) {
                            return a.fragment.triangle == b.fragment.triangle && a.fragment.uv_area == b.fragment.uv_area;
                          });
        if (!same) ++wrong;
      }
    };
    detail::for_each_texel_patch(rs, s, cov, fn, {}, [&]<int N>() { return Worker{s, cov, visits, wrong_fragments, {}}; });
    for (std::size_t t = 0; t < cov.texel_count(); ++t) EXPECT_EQ(visits[t].load(), cov.mask[t] ? 1 : 0) << w << "x" << h << " texel " << t;
    EXPECT_EQ(wrong_fragments.load(), 0) << w << "x" << h;
    EXPECT_GT(cov.covered_texels, cov.texel_count() / 2);
  }
}

// With a distance limit, the ray-traced baker matches the foundation's step-membership wall formula
// V = 1 - (acos(a) - a sqrt(1-a^2))/pi for a = d/R <= 1 (infinite wall).
TEST(Bake, TexelRayBatchesAreTheRaysOfTheScalarSamplingPath) {
  // make_texel_rays (lane-parallel, polynomial sine and cosine) against sample_patch, Frame and
  // cosine_hemisphere one sample at a time, on a quad with bent vertex normals whose texels
  // straddle its diagonal (patches of one and several pieces, from PatchTable), on a 2 x 3 grid of
  // bumpy quads baked into one texel (12 pieces: more than a vector of 4 or 8 lanes holds, fewer
  // than PatchTable's 16), and on a 4 x 4 grid (32 pieces: more than PatchTable holds, so read
  // piece by piece). Tolerance 1e-5: float rounding of unit vectors and unit-sized positions, plus
  // the polynomials' error (< 1e-7).
  const auto bumpy_grid = [](std::uint32_t nx, std::uint32_t ny) {
    Mesh grid;
    for (std::uint32_t j = 0; j <= ny; ++j)
      for (std::uint32_t i = 0; i <= nx; ++i) {
        const float x = static_cast<float>(i) / static_cast<float>(nx), y = static_cast<float>(j) / static_cast<float>(ny);
        grid.positions.push_back({x, y, 0.1f * std::sin(6 * x) * std::cos(5 * y)});
        grid.normals.push_back(normalize(Vec3{-0.6f * std::cos(6 * x) * std::cos(5 * y), 0.5f * std::sin(6 * x) * std::sin(5 * y), 1}));
        grid.uvs.push_back({x, y});
      }
    for (std::uint32_t j = 0; j < ny; ++j)
      for (std::uint32_t i = 0; i < nx; ++i) {
        const std::uint32_t a = j * (nx + 1) + i;
        grid.indices.insert(grid.indices.end(), {a, a + 1, a + nx + 2, a, a + nx + 2, a + nx + 1});
      }
    return grid;
  };
  Mesh m = uv_quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0.3f}, {0, 1, 0}, {0, 0}, {1, 1});
  m.normals = {normalize(Vec3{0.3f, 0, 1}), normalize(Vec3{-0.2f, 0.4f, 1}), normalize(Vec3{0, -0.6f, 1}), {0, 0, 1}};
  int multi = 0, many = 0, between = 0;
  for (const auto& [mesh, size] : {std::pair{m, 5}, std::pair{bumpy_grid(2, 3), 1}, std::pair{bumpy_grid(4, 4), 1}}) {
    Scene s;
    s.meshes.push_back(mesh);
    s = prepared(std::move(s));
    const TexelCoverage cov = compute_texel_coverage(s, size);
    const detail::TriangleNormals fn = detail::face_normals(s);
    std::vector<detail::PatchPiece> patch;
    std::vector<TexelPiece> fragments;
    for (bool geometric : {false, true})
      for (float fixed : {0.0f, 0.01f})
        for (std::size_t texel = 0; texel < cov.texel_count(); ++texel) {
          if (!cov.mask[texel]) continue;
          texel_fragments(s, cov, texel, fragments);
          detail::build_patch(s, cov, fn, fragments, patch);
          if (patch.empty()) continue;
          multi += patch.size() > 1;
          many += patch.size() > static_cast<std::size_t>(detail::PatchTable::kMaxPieces);
          between += patch.size() > 8 && patch.size() <= static_cast<std::size_t>(detail::PatchTable::kMaxPieces);
          const std::uint32_t key = pixel_seed(3, static_cast<int>(texel), 0);
          for (std::uint32_t first = 0; first < 48; first += 16) {
            const int count = first == 32 ? 11 : 16;
            detail::TexelRayBatch b;
            float lanes[4][16];
            sobol_owen_4d_batch(first, count, key, lanes);
            detail::PatchTable table;
            table.build(patch, fixed);
            detail::make_texel_rays(patch, table, lanes, count, geometric, b);
            for (int k = 0; k < 16; ++k) {
              if (k >= count) {
                EXPECT_EQ(b.valid[k], 0);
                continue;
              }
              const std::array<float, 4> u = sobol_owen_4d(first + static_cast<std::uint32_t>(k), key);
              const detail::PatchSample ps = detail::sample_patch(patch, {u[2], u[3]});
              const Vec3 ng = ps.piece->ng;
              const Vec3 d = Frame::from_normal(geometric ? ng : ps.normal()).to_world(cosine_hemisphere({u[0], u[1]}));
              const Vec3 o = ps.position() + ng * (fixed > 0 ? fixed : ps.piece->offset);
              if (std::abs(dot(d, ng)) > 1e-5f) {
                EXPECT_EQ(b.valid[k] != 0, dot(d, ng) > 0) << "texel " << texel << " sample " << first + k;
              }
              EXPECT_NEAR(b.dx[k], d.x, 1e-5f);
              EXPECT_NEAR(b.dy[k], d.y, 1e-5f);
              EXPECT_NEAR(b.dz[k], d.z, 1e-5f);
              EXPECT_NEAR(b.ox[k], o.x, 1e-5f);
              EXPECT_NEAR(b.oy[k], o.y, 1e-5f);
              EXPECT_NEAR(b.oz[k], o.z, 1e-5f);
            }
          }
        }
  }
  EXPECT_GT(multi, 0);  // every lookup was exercised
  EXPECT_GT(many, 0);
  EXPECT_GT(between, 0);
}

// PackedTracer fills packets with the rays of consecutive texels and hands the samples back in
// the order they came, each texel's end after its samples (a hundred texels with none among them):
// against every ray traced alone
// (Tracer::trace<1>), at every packet width a machine may have (1, 4, 8, 16), for an
// occlusion-only tracer and one with a falloff (the path that packs rays itself), with texels of
// 1 to 40 samples (packets shared by up to 16 texels, and texels spread over three packets) whose
// batches have lanes with no ray (mu 0), and texels ended while rays of theirs wait in an open packet.
template <int N>
void expect_packed_tracer_keeps_each_texels_samples(const detail::Tracer& tracer) {
  struct Recorder {
    std::vector<std::pair<std::uint32_t, float>> got;  // (tag, mu) per sample; (texel, -1) per texel end
    void sample(const typename detail::PackedTracer<N>::Sample& e) { got.emplace_back(e.tag, e.mu); }
    void texel_done(std::uint32_t texel) { got.emplace_back(texel, -1.0f); }
  } recorder;
  std::vector<std::pair<std::uint32_t, float>> expected;
  detail::PackedTracer<N> packed(tracer, true, false);
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  std::uint32_t state = 7, tag = 0;
  const auto next = [&] { return (state = state * 1664525u + 1013904223u) >> 8; };
  for (std::uint32_t texel = 0; texel < 400; ++texel) {
    // Texels 200-299 but 250 have no samples (high to low's texels whose cage points all miss),
    // and 250 has one: the runs before and after it end while rays wait in the stream (its fill
    // after 199 and after 250 differ by one, so at most one of them is empty).
    const int samples = texel == 250 ? 1 : texel >= 200 && texel < 300 ? 0 : texel % 7 == 0 ? 40 : 1 + static_cast<int>(next() % 9);
    for (int first = 0; first < samples; first += 16) {
      const int count = std::min(16, samples - first);
      detail::TexelRayBatch b;
      std::uint32_t tags[16];
      for (int k = 0; k < count; ++k) {
        // Floor points before the wall (floor_and_wall), directions over the upper hemisphere:
        // some blocked, some open.
        const float x = static_cast<float>(next() % 1000) / 1000 - 0.5f, z = static_cast<float>(next() % 1000) / 1000;
        const float a = static_cast<float>(next() % 6283) / 1000, c = static_cast<float>(next() % 1000) / 1000;
        const Vec3 d = normalize(Vec3{std::cos(a) * std::sqrt(1 - c * c), c, std::sin(a) * std::sqrt(1 - c * c)});
        b.ox[k] = x, b.oy[k] = 1e-4f, b.oz[k] = z, b.dx[k] = d.x, b.dy[k] = d.y, b.dz[k] = d.z;
        b.valid[k] = next() % 5 == 0 ? 0 : -1;
        tags[k] = tag++;
        float mu = 0.0f;
        const Vec3 o{x, 1e-4f, z};
        if (b.valid[k]) tracer.trace<1>(ctx, &o, &d, 1, &mu);
        expected.emplace_back(tags[k], mu);
      }
      packed.add(ctx, b, count, tags, recorder);
    }
    packed.end_texel(texel, recorder);
    expected.emplace_back(texel, -1.0f);
  }
  packed.flush(ctx, recorder);
  ASSERT_EQ(recorder.got.size(), expected.size());
  int open = 0, blocked = 0;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(recorder.got[i], expected[i]) << "entry " << i << " at width " << N;
    open += expected[i].second == 1.0f, blocked += expected[i].second == 0.0f;
  }
  EXPECT_GT(open, 100);  // both outcomes were traced
  EXPECT_GT(blocked, 100);
}

TEST(Bake, PackedTracerHandsBackEachTexelsSamplesInOrderWithTheirOwnMu) {
  const Scene s = floor_and_wall(0.5f);
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  const detail::TriangleNormals fn = detail::face_normals(s);
  for (const Falloff falloff : {Falloff{Membership::Step, kInfinity}, Falloff{Membership::Linear, 0.8f}}) {
    const detail::Tracer tracer{rs, falloff, fn, false};
    expect_packed_tracer_keeps_each_texels_samples<1>(tracer);
    expect_packed_tracer_keeps_each_texels_samples<4>(tracer);
    expect_packed_tracer_keeps_each_texels_samples<8>(tracer);
    expect_packed_tracer_keeps_each_texels_samples<16>(tracer);
  }
}

// The texels of a 4 x 4 block share one sequence, each its own n points of it: at n = 16 each
// texel's directions put one point in every cell of a 4 x 4 grid over dimensions 0-1 (its own net),
// and the block's 256 put one in every cell of a 16 x 16 grid (one net together, which sixteen
// independent sets would not be). Texels of other blocks take other sequences.
TEST(Bake, TexelsOfABlockShareOneStratifiedSequence) {
  constexpr int kSamples = 16;
  std::set<std::pair<int, int>> block_cells;
  std::set<std::uint32_t> first;
  for (int y = 8; y < 12; ++y)
    for (int x = 4; x < 8; ++x) {
      const detail::TexelSampleSet set = detail::texel_sample_set(1u, x, y, kSamples);
      EXPECT_EQ(set.key, detail::texel_sample_set(1u, 4, 8, kSamples).key);
      first.insert(set.first);
      std::set<std::pair<int, int>> own;
      for (int i = 0; i < kSamples; ++i) {
        const std::array<float, 4> u = sobol_owen_4d(set.first + static_cast<std::uint32_t>(i), set.key);
        own.insert({static_cast<int>(u[0] * 4), static_cast<int>(u[1] * 4)});
        block_cells.insert({static_cast<int>(u[0] * 16), static_cast<int>(u[1] * 16)});
      }
      EXPECT_EQ(own.size(), 16u) << "texel " << x << ", " << y;
    }
  EXPECT_EQ(first.size(), 16u);
  EXPECT_EQ(block_cells.size(), 256u);
  EXPECT_NE(detail::texel_sample_set(1u, 8, 8, kSamples).key, detail::texel_sample_set(1u, 4, 8, kSamples).key);
  EXPECT_NE(detail::texel_sample_set(1u, 4, 12, kSamples).key, detail::texel_sample_set(1u, 4, 8, kSamples).key);
}

TEST(Bake, TexelPointsAreTheSobolSetInDirectionCells) {
  // The order holds the same points as index order (so the texel's mean is unchanged), and at a
  // power-of-two count every packet of 16 lies in one cell of the direction grid (the net
  // property, which an aligned block of the sequence has as its start does: texel (3, 2) of its
  // block takes points [11 n, 12 n)); at other counts the order is still a permutation.
  detail::TexelPoints pts;
  for (int samples : {64, 256, 128, 37}) {
    const detail::TexelSampleSet set = detail::texel_sample_set(7u, 3, 2, samples);
    ASSERT_EQ(set.first, 11u * static_cast<std::uint32_t>(samples));
    pts.generate(set, samples);
    std::vector<std::array<float, 4>> want, got;
    for (int i = 0; i < samples; ++i) {
      want.push_back(sobol_owen_4d(set.first + static_cast<std::uint32_t>(i), set.key));
      got.push_back({pts.u[0][static_cast<std::size_t>(i)], pts.u[1][static_cast<std::size_t>(i)], pts.u[2][static_cast<std::size_t>(i)],
                     pts.u[3][static_cast<std::size_t>(i)]});
    }
    std::sort(want.begin(), want.end());
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, want) << samples;
    if ((samples & (samples - 1)) != 0) continue;
    const int cells = samples / 16;
    const int cols = samples == 128 ? 4 : static_cast<int>(std::lround(std::sqrt(cells))), rows = cells / cols;
    for (int first = 0; first < samples; first += 16) {
      std::set<int> cell;
      for (int k = first; k < first + 16; ++k)
        cell.insert(static_cast<int>(pts.u[0][static_cast<std::size_t>(k)] * cols) * rows + static_cast<int>(pts.u[1][static_cast<std::size_t>(k)] * rows));
      EXPECT_EQ(cell.size(), 1u) << samples << " samples, packet at " << first;
    }
  }
}

TEST(Bake, RaytracedDistanceLimitMatchesWallFormula) {
  const Scene s = floor_and_wall(40.0f);
  const int n = 8;
  const TexelCoverage cov = compute_texel_coverage(s, n);
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  const float R = 2.0f;
  const BakeResult r = bake_raytraced(rs, cov, {.samples = 2048, .max_distance = R});
  for (int y = 0; y < n; ++y) {
    double truth = 0;  // texel average over its row of distances, midpoint rule
    for (int k = 0; k < 32; ++k) {
      const double a = (1.0 - (y + (k + 0.5) / 32) / n) / R;
      truth += (1 - (std::acos(a) - a * std::sqrt(1 - a * a)) / kPi) / 32;
    }
    double mean = 0;
    for (int x = 0; x < n; ++x) mean += r.visibility(x, y) / n;
    EXPECT_NEAR(mean, truth, 0.01) << "row " << y;  // 8 x 2048 rays: std. error ~0.004
  }
}

// Stretch correction (sec. 3.1) + exact normalisation: a layout whose texels cover different
// amounts of surface bakes to the same V at the same surface points.
TEST(Bake, StretchedAndUnstretchedLayoutsAgree) {
  const int n = 16;
  // A wall 4 wide (the layouts are compared with each other, not with the infinite wall's view
  // factor): the histogram baker's views span the scene, so a narrow one bakes 10x faster.
  const Scene plain = floor_and_wall(0.5f, false, 2.0f), stretched = floor_and_wall(0.5f, true, 2.0f);
  const HistogramParams p{.directions = 1024, .pixels_per_texel = 2.0f};
  const BakeResult a = bake_histogram(plain, compute_texel_coverage(plain, n), p);
  const BakeResult b = bake_histogram(stretched, compute_texel_coverage(stretched, n), p);
  // Compare at floor distances d: row of d in each layout, averaged over the row.
  auto row_mean = [&](const BakeResult& r, int y) {
    double m = 0;
    for (int x = 0; x < n; ++x) m += r.visibility(x, y) / n;
    return m;
  };
  for (double d : {0.1, 0.3, 0.45, 0.6, 0.8, 0.95}) {
    const int ya = std::min(n - 1, static_cast<int>((1.0 - d) * n));
    const double v = d < 0.5 ? d * 1.5 : 0.75 + (d - 0.5) * 0.5;
    const int yb = std::min(n - 1, static_cast<int>((1.0 - v) * n));
    // Texels of the two layouts cover different spans of d; V changes by < 0.02 across a texel
    // here, plus the noise of 16 texels at 1024 directions.
    EXPECT_NEAR(row_mean(a, ya), row_mean(b, yb), 0.03) << "d = " << d;
  }
}

// Runs `bake` at 1 and at 2 threads: every texel's V and bent normal must match bit for bit.
template <class Bake>
void expect_identical_at_one_and_two_threads(Bake&& bake) {
  auto at = [&](std::size_t threads) {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, threads);
    return bake();
  };
  const BakeResult one = at(1), two = at(2);
  for (std::size_t i = 0; i < one.visibility.size(); ++i) {
    EXPECT_EQ(one.visibility[i], two.visibility[i]);
    EXPECT_EQ(one.bent_normal[i], two.bent_normal[i]);
  }
}

// The ray-traced baker reports progress in covered texels (the texels that cast rays), not in
// texels of the map: on a chart covering a quarter of the map it ends at the covered count.
TEST(Bake, RaytracedProgressCountsCoveredTexels) {
  Scene s;
  s.meshes.push_back(uv_quad({-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}, {0, 0}, {0.5f, 0.5f}));
  s = prepared(std::move(s));
  const TexelCoverage cov = compute_texel_coverage(s, 32);
  ASSERT_EQ(cov.covered_texels, 256u);
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  std::atomic<std::size_t> last_done{0}, last_total{0};
  bake_raytraced(rs, cov, {.samples = 4}, [&](std::size_t done, std::size_t total) {
    std::size_t seen = last_done.load();
    while (done > seen && !last_done.compare_exchange_weak(seen, done)) {
    }
    last_total = total;
  });
  EXPECT_EQ(last_total.load(), 256u);
  EXPECT_EQ(last_done.load(), 256u);
}

TEST(Bake, HistogramIsIdenticalAtOneAndTwoThreads) {
  const Scene s = floor_and_wall(1.0f);
  const TexelCoverage cov = compute_texel_coverage(s, 16);
  const HistogramParams p{.directions = 64, .bent_normals = true};
  expect_identical_at_one_and_two_threads([&] { return bake_histogram(s, cov, p); });
}

TEST(Bake, RaytracedIsIdenticalAtOneAndTwoThreads) {
  const Scene s = floor_and_wall(1.0f);
  const TexelCoverage cov = compute_texel_coverage(s, 16);
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  const RaytracedBakeParams p{.samples = 48, .bent_normals = true, .seed = 5};
  expect_identical_at_one_and_two_threads([&] { return bake_raytraced(rs, cov, p); });
}

TEST(Bake, DenoisedRaytracedIsIdenticalAtOneAndTwoThreads) {
  const Scene s = floor_and_wall(1.0f);
  const TexelCoverage cov = compute_texel_coverage(s, 16);
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  const RaytracedBakeParams p{.samples = 16, .bent_normals = true, .seed = 5, .denoise = 1.0f};
  expect_identical_at_one_and_two_threads([&] { return bake_raytraced(rs, cov, p); });
}

// A floor under a ceiling at height d, occluders counted within R (a step): a direction at angle t
// from the normal meets the ceiling within R when d / cos t <= R, and the cosine-weighted share of
// cos t >= d / R is 1 - (d / R)^2, so V = (d / R)^2 at every floor point whose ceiling reaches
// sqrt(R^2 - d^2) beyond it. Floor: x, z in [-2, 2], facing up, UVs u in [u0, u1] over the whole
// height of the map; ceiling: a slab whose underside is at y = d over x, z in [-8, 8].
constexpr float kCeilingHeight = 0.5f, kCeilingReach = 1.0f;
constexpr double kUnderCeiling = 0.25;  // (d / R)^2

Mesh floor_chart(float x0, float u0, float u1) {
  return uv_quad({x0, 0, 2}, {x0 + 4, 0, 2}, {x0 + 4, 0, -2}, {x0, 0, -2}, {u0, 1}, {u1, 0});
}
Mesh ceiling() { return make_box({-8, kCeilingHeight, -8}, {8, kCeilingHeight + 0.2f, 8}); }

struct MapError {
  double rmse = 0, mean = 0;
};
// RMSE against `truth` and mean over the covered texels of columns [x0, x1).
MapError map_error(const BakeResult& r, int x0, int x1, double truth) {
  double se = 0, sum = 0;
  int n = 0;
  for (int y = 0; y < r.visibility.height(); ++y)
    for (int x = x0; x < x1; ++x)
      if (r.mask(x, y)) {
        se += (r.visibility(x, y) - truth) * (r.visibility(x, y) - truth);
        sum += r.visibility(x, y);
        ++n;
      }
  return {std::sqrt(se / n), sum / n};
}

// The filter averages the noise of neighbouring texels of one surface and keeps the mean: on a
// surface of constant V, 16 rays per texel, its error against the exact V must fall by more than
// half (a Gaussian of sigma 1 texel weighs about 12 texels' worth: about a third of the noise in
// the interior), and both means stay at V (16 x 32 x 32 samples: standard error ~0.002).
TEST(Bake, DenoisingAveragesNoiseAndKeepsTheExactMean) {
  Scene s;
  s.meshes = {floor_chart(-2, 0, 1), ceiling()};
  s = prepared(std::move(s));
  const TexelCoverage cov = compute_texel_coverage(s, 32);
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  const RaytracedBakeParams plain{.samples = 16, .max_distance = kCeilingReach};
  RaytracedBakeParams filtered = plain;
  filtered.denoise = 1.0f;
  const MapError e0 = map_error(bake_raytraced(rs, cov, plain), 0, 32, kUnderCeiling);
  const MapError e1 = map_error(bake_raytraced(rs, cov, filtered), 0, 32, kUnderCeiling);
  EXPECT_GT(e0.rmse, 0.02);  // there is noise to remove
  EXPECT_LT(e1.rmse, 0.5 * e0.rmse);
  EXPECT_NEAR(e0.mean, kUnderCeiling, 0.01);
  EXPECT_NEAR(e1.mean, kUnderCeiling, 0.01);
}

// A contact shadow's edge on one flat chart: the floor of floor_and_wall extended under the wall
// (a closed box standing on it), so the floor is 0 under the wall (every ray meets the box's inside)
// and, just outside, the wall's view factor, about 1/2: a step of one texel. Rows are 1/16 apart
// and the wall's face lies on a row boundary. The value term keeps the filter from averaging across
// the step (a Gaussian alone would pull both rows next to it about 0.1 towards each other); each row
// must stay within 0.03 of its exact texel average (32 texels x 64 rays: standard error ~0.005).
TEST(Bake, DenoisingKeepsTheEdgeOfAContactShadow) {
  Scene s;
  s.meshes = {uv_quad({-0.5f, 0, 1}, {0.5f, 0, 1}, {0.5f, 0, -1}, {-0.5f, 0, -1}, {0, 1}, {1, 0}), make_box({-20, 0, -1.5f}, {20, 1, 0})};
  s = prepared(std::move(s));
  const int n = 32;
  const TexelCoverage cov = compute_texel_coverage(s, n);
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  const BakeResult r = bake_raytraced(rs, cov, {.samples = 64, .denoise = kDefaultBakeDenoise});
  auto row_mean = [&](int y) {
    double sum = 0;
    for (int x = 0; x < n; ++x) sum += r.visibility(x, y);
    return sum / n;
  };
  // Row y covers z in [1 - (y + 1) / 16, 1 - y / 16]: row 15 is the first outside the wall, row 16 the first under it.
  double outside = 0;
  for (int k = 0; k < 64; ++k) outside += wall_visibility((k + 0.5) / 64 / 16, 1.0) / 64;
  EXPECT_NEAR(row_mean(15), outside, 0.03);
  EXPECT_NEAR(row_mean(16), 0.0, 0.03);
}

// A unit cube standing on a 4 x 4 floor, each of the six faces its own chart in a 3 x 3 grid of the
// map (bench/tools/box_on_floor_obj.py writes the same scene as an OBJ). The texels at the contact,
// by side: `floor_contact`, floor texels whose centre lies within 1.5 texels of the cube's footprint
// outline (on either side: V = 0 under the cube, about 1/2 beside it), and `side_contact`, side
// texels within 1.5 texels of the floor (bench/blender/box_contacts.py marks the same texels in a
// baked file).
struct BoxOnFloor {
  Scene scene;
  int n = 0;
  std::vector<bool> floor_contact, side_contact;
};

BoxOnFloor box_on_floor(int n) {
  constexpr float side = 1.0f / 3, margin = 0.01f, lo = -0.5f, hi = 0.5f, top = 1.0f;
  auto chart = [&](Vec3 p0, Vec3 p1, Vec3 p2, Vec3 p3, int cx, int cy) {
    return uv_quad(p0, p1, p2, p3, {cx * side + margin, cy * side + margin}, {cx * side + side - margin, cy * side + side - margin});
  };
  BoxOnFloor b;
  b.n = n;
  b.scene.meshes = {chart({-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, {-2, 0, -2}, 0, 0),      // floor
                    chart({lo, top, hi}, {hi, top, hi}, {hi, top, lo}, {lo, top, lo}, 1, 0),  // top
                    chart({lo, 0, hi}, {hi, 0, hi}, {hi, top, hi}, {lo, top, hi}, 2, 0),      // +z
                    chart({hi, 0, lo}, {lo, 0, lo}, {lo, top, lo}, {hi, top, lo}, 0, 1),      // -z
                    chart({hi, 0, hi}, {hi, 0, lo}, {hi, top, lo}, {hi, top, hi}, 1, 1),      // +x
                    chart({lo, 0, lo}, {lo, 0, hi}, {lo, top, hi}, {lo, top, lo}, 2, 1)};     // -x
  b.scene = prepared(std::move(b.scene));
  const float chart_texels = (side - 2 * margin) * static_cast<float>(n);
  b.floor_contact.assign(static_cast<std::size_t>(n) * n, false);
  b.side_contact = b.floor_contact;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const float u = (x + 0.5f) / n, v = 1.0f - (y + 0.5f) / n;
      const int cx = static_cast<int>(u / side), cy = static_cast<int>(v / side);
      const float a = (u - cx * side - margin) / (side - 2 * margin), c = (v - cy * side - margin) / (side - 2 * margin);
      if (a < 0 || a > 1 || c < 0 || c > 1) continue;
      const std::size_t texel = static_cast<std::size_t>(y) * n + x;
      if (cx == 0 && cy == 0) {  // the floor: world x = -2 + 4a, z = 2 - 4c; texels of 4 / chart_texels
        const float px = std::abs(-2 + 4 * a), pz = std::abs(2 - 4 * c);
        const float outside = std::hypot(std::max(px - hi, 0.0f), std::max(pz - hi, 0.0f));
        const float distance = outside > 0 ? outside : hi - std::max(px, pz);
        b.floor_contact[texel] = distance <= 1.5f * 4 / chart_texels;
      } else if (!(cx == 1 && cy == 0)) {  // a side: height c, texels of 1 / chart_texels
        b.side_contact[texel] = c <= 1.5f / chart_texels;
      }
    }
  return b;
}

// The filter's value term weighs each texel's neighbours by how far apart a first, narrow filtering
// of the map (the guide, denoise.h) puts them against the noise measured in their own samples
// (StratifiedVariance), so that at 64 rays the default filter keeps the contact shadows of a box on
// a floor at least as sharp as unfiltered while the whole map's RMSE falls at least 2-fold. RMSE
// against a 1024-ray bake with another seed, by side: the box's sides at the floor, where the shadow
// runs along the chart's edge, and the floor beside the box, where V climbs from about 1/2 to 0.9
// across a few texels of the chart (docs/methods/bake.md, "Denoising").
TEST(Bake, DenoisingKeepsTheContactEdgesOfABoxOnAFloor) {
  const BoxOnFloor b = box_on_floor(256);
  const TexelCoverage cov = compute_texel_coverage(b.scene, b.n);
  const RayScene rs(b.scene, bake_bvh_options(b.scene.triangle_count()));
  const BakeResult reference = bake_raytraced(rs, cov, {.samples = 1024, .seed = 99});
  const BakeResult plain = bake_raytraced(rs, cov, {.samples = 64});
  const BakeResult filtered = bake_raytraced(rs, cov, {.samples = 64, .denoise = kDefaultBakeDenoise});
  auto rmse = [&](const BakeResult& r, const std::vector<bool>* texels) {
    double se = 0;
    int count = 0;
    for (std::size_t i = 0; i < r.visibility.size(); ++i) {
      if (!cov.mask[i] || (texels && !(*texels)[i])) continue;
      se += (r.visibility[i] - reference.visibility[i]) * (r.visibility[i] - reference.visibility[i]);
      ++count;
    }
    return std::sqrt(se / count);
  };
  const double floor_plain = rmse(plain, &b.floor_contact), floor_filtered = rmse(filtered, &b.floor_contact);
  const double side_plain = rmse(plain, &b.side_contact), side_filtered = rmse(filtered, &b.side_contact);
  const double all_plain = rmse(plain, nullptr), all_filtered = rmse(filtered, nullptr);
  EXPECT_LE(floor_filtered, floor_plain);  // 0.0113 against 0.0124 (sigma 1: 0.0105; one pass 0.0120, a weighted mean 0.0132)
  EXPECT_LE(side_filtered, side_plain);
  EXPECT_LT(all_filtered * 2, all_plain);
}

// A flat chart of w x h texels, one world unit each: a quad holding the whole UV square, its
// coverage, and guides with each texel's centre and the normal up (variances 0, for the test to set).
struct FlatChart {
  TexelCoverage cov;
  TexelGuides guides;
};
FlatChart flat_chart(int w, int h) {
  const auto fw = static_cast<float>(w), fh = static_cast<float>(h);
  Scene s;
  s.meshes = {uv_quad({0, 0, fh}, {fw, 0, fh}, {fw, 0, 0}, {0, 0, 0}, {0, 0}, {1, 1})};
  s = prepared(std::move(s));
  FlatChart c{compute_texel_coverage(s, w, h), {}};
  c.guides = TexelGuides(c.cov.mask);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      c.guides.position[c.guides.slot(x, y)] = {static_cast<float>(x) + 0.5f, 0, static_cast<float>(h - y) - 0.5f};
      c.guides.normal[c.guides.slot(x, y)] = {0, 1, 0};
    }
  return c;
}

// The filter fits a plane to each texel's window (denoise.h), so a linear ramp in V keeps its level
// where the window is one-sided: on a flat 16 x 8 chart with V = 0.1 + 0.05 x and a large measured
// variance (the value term weighs ~1), the texels of the left border column (their neighbours all
// lie at dx >= 0) move by at most 0.6 of what a Gaussian-weighted mean would move them (0.503
// texels of slope, 0.025), and the interior, whose windows are symmetric, does not move.
TEST(Bake, DenoisingKeepsALinearRampAtTheBorderOfAChart) {
  constexpr int kW = 16, kH = 8;
  constexpr float kSlope = 0.05f;
  auto [cov, guides] = flat_chart(kW, kH);
  ASSERT_EQ(cov.covered_texels, static_cast<std::size_t>(kW * kH));
  Image<float> v(kW, kH, 0.0f);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      guides.variance[guides.slot(x, y)] = 100.0f;
      v(x, y) = 0.1f + kSlope * static_cast<float>(x);
    }
  const Image<float> before = v;
  denoise_map(v, cov.mask, cov, guides, 1.0f);
  // The Gaussian-weighted mean's shift at the border: the mean offset of a one-sided window of
  // radius 2 (the y offsets cancel).
  double g_sum = 0, g_dx = 0;
  for (int dx = 0; dx <= 2; ++dx) g_sum += std::exp(-0.5 * dx * dx), g_dx += dx * std::exp(-0.5 * dx * dx);
  const double mean_shift = kSlope * g_dx / g_sum;
  ASSERT_NEAR(mean_shift, 0.0252, 1e-4);
  for (int y = 2; y < kH - 2; ++y) {
    EXPECT_LE(std::abs(v(0, y) - before(0, y)), 0.6 * mean_shift) << "row " << y;
    for (int x = 2; x < kW - 2; ++x) EXPECT_NEAR(v(x, y), before(x, y), 1e-5) << x << ", " << y;
  }
}

// The filter keeps a noisy map's mean. A flat 64 x 64 chart with V = 0.8 everywhere, each texel the
// mean of 8 samples (1 with probability 0.8) with its sample variance of the mean, p (1 - p) / 7:
// the closer a texel's value lies to 1, the less noise it measures, so a texel noisy upward takes
// fewer of its neighbours than one noisy downward, and keeps more of its own value. Compared with
// their own values, as the filter did in one pass, the texels lift the mean by 7.0e-4 at sigma 3
// (the elephant's 8-ray maps: +5e-4 above converged); compared through the guide, whose values and
// variances are averages over the first pass's window, by 1.4e-4. Bound: 4e-4.
TEST(Bake, DenoisingKeepsTheMeanOfANoisyChart) {
  constexpr int kN = 64, kSamples = 8;
  auto [cov, guides] = flat_chart(kN, kN);
  ASSERT_EQ(cov.covered_texels, static_cast<std::size_t>(kN * kN));
  Image<float> v(kN, kN, 0.0f);
  std::uint32_t state = 12345u;
  double before = 0;
  for (int y = 0; y < kN; ++y)
    for (int x = 0; x < kN; ++x) {
      int escaped = 0;
      for (int k = 0; k < kSamples; ++k) {
        state = state * 1664525u + 1013904223u;  // a fixed LCG: the same map on every platform
        escaped += (state >> 8) < static_cast<std::uint32_t>(0.8 * (1u << 24)) ? 1 : 0;
      }
      const float p = static_cast<float>(escaped) / kSamples;
      v(x, y) = p;
      guides.variance[guides.slot(x, y)] = p * (1 - p) / (kSamples - 1);  // the sample variance of the mean
      before += p;
    }
  before /= kN * kN;
  denoise_map(v, cov.mask, cov, guides, 3.0f);
  double after = 0;
  for (int y = 0; y < kN; ++y)
    for (int x = 0; x < kN; ++x) after += v(x, y);
  after /= kN * kN;
  EXPECT_NEAR(before, 0.8, 0.01);
  EXPECT_LE(std::abs(after - before), 4e-4) << "mean " << before << " -> " << after;
}

// Two charts side by side in UV, far apart on the surface: the floor under the ceiling (V = 1/4)
// on the left half of the map and a floor in the open (V = 1, every ray misses) on the right, in
// the same plane with the same normal, so only the distance on the surface tells them apart. The
// filter must not mix them: the open chart stays exactly 1 and the column of the covered chart
// next to the UV border keeps its mean.
TEST(Bake, DenoisingDoesNotMixChartsThatAreOnlyNeighboursInUv) {
  Scene s;
  s.meshes = {floor_chart(-2, 0, 0.5f), floor_chart(50, 0.5f, 1), ceiling()};
  s = prepared(std::move(s));
  const TexelCoverage cov = compute_texel_coverage(s, 32);
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  const BakeResult r = bake_raytraced(rs, cov, {.samples = 64, .max_distance = kCeilingReach, .denoise = 2.0f});
  for (int y = 0; y < 32; ++y)
    for (int x = 16; x < 32; ++x) EXPECT_EQ(r.visibility(x, y), 1.0f) << x << ", " << y;
  EXPECT_NEAR(map_error(r, 15, 16, kUnderCeiling).mean, kUnderCeiling, 0.02);  // 32 texels x 64 rays; leaking 1s would give ~0.4
}

// The bake's quad BVH (bake_bvh_options pairs triangles into quads) traces the same rays to the
// same answers as a BVH of the triangles: occlusion packets (the default), closest hits through
// back faces (ignore_back_faces maps each hit back to its triangle for the face normal) and
// distances (a linear membership). Occluders: a sphere and a torus, curved, so a quad's two
// halves face different ways.
TEST(Bake, QuadBvhBakesTheTriangleBvhsMap) {
  Scene s;
  s.meshes.push_back(uv_quad({-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, {-2, 0, -2}, {0, 0}, {1, 1}));
  s.meshes.push_back(make_sphere({0.5f, 0.6f, 0.3f}, 0.5f, 20, 9));
  s.meshes.push_back(make_torus({-0.8f, 0.3f, -0.5f}, 0.6f, 0.2f, 17, 7));
  s = prepared(std::move(s));
  const TexelCoverage cov = compute_texel_coverage(s, 24);
  const RayScene quads(s, bake_bvh_options(s.triangle_count()));
  ASSERT_TRUE(quads.quads());
  const RayScene tris(s, {});
  ASSERT_FALSE(tris.quads());
  const RaytracedBakeParams cases[] = {{.samples = 64},
                                       {.samples = 32, .ignore_back_faces = true},
                                       {.samples = 32, .max_distance = 1.0f, .membership = Membership::Linear}};
  for (const RaytracedBakeParams& p : cases) {
    const BakeResult want = bake_raytraced(tris, cov, p);
    const BakeResult got = bake_raytraced(quads, cov, p);
    double darkened = 0;  // how much the occluders take off the map, to show the case tests something
    int differ = 0;
    for (std::size_t i = 0; i < want.visibility.size(); ++i) {
      if (!want.mask[i]) continue;
      darkened += 1.0 - want.visibility[i];
      // A ray that grazes an edge two triangles share may be answered differently (the order of
      // the two intersection tests changes): at most a sample or two of a texel.
      EXPECT_NEAR(got.visibility[i], want.visibility[i], 2.0 / p.samples) << "texel " << i;
      differ += got.visibility[i] != want.visibility[i];
    }
    EXPECT_GT(darkened, 10.0);
    EXPECT_LT(differ, static_cast<int>(want.covered_texels / 50)) << "texels not bit-identical";
  }
}

// The texel error against the analytic texel average falls faster than Monte Carlo's N^-1/2:
// the jointly stratified (point, direction) samples give about N^-3/4 on this scene (an
// indicator over the hemisphere: Owen-scrambled nets' rate for integrands with a discontinuity).
// From 16 to 256 rays MC would divide the RMSE by 4, N^-3/4 by 8; the test asks for more than 5.5.
TEST(Bake, RaytracedErrorFallsFasterThanMonteCarlo) {
  const Scene s = floor_and_wall(1.0f);
  const int n = 16;
  const TexelCoverage cov = compute_texel_coverage(s, n);
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  auto rmse = [&](int samples) {
    double se = 0;
    int count = 0;
    for (std::uint32_t seed = 1; seed <= 4; ++seed) {
      const BakeResult r = bake_raytraced(rs, cov, {.samples = samples, .seed = seed});
      for (int y = 0; y < n; ++y) {
        double truth = 0;  // texel average over its row of distances to the wall, midpoint rule on 64 points
        for (int k = 0; k < 64; ++k) truth += wall_visibility(1.0 - (y + (k + 0.5) / 64) / n, 1.0) / 64;
        for (int x = 0; x < n; ++x) {
          se += (r.visibility(x, y) - truth) * (r.visibility(x, y) - truth);
          ++count;
        }
      }
    }
    return std::sqrt(se / count);
  };
  const double e16 = rmse(16), e256 = rmse(256);
  EXPECT_GT(e16 / e256, 5.5) << "RMSE " << e16 << " at 16 rays, " << e256 << " at 256";
}

TEST(Bake, MaxNormalizationPutsTheBrightestTexelAtOne) {
  const Scene s = floor_and_wall(1.0f);
  const TexelCoverage cov = compute_texel_coverage(s, 16);
  const BakeResult h = bake_histogram(s, cov, {.directions = 128, .normalization = BakeNormalization::Max, .seam_fix = false});
  float mx = 0;
  for (float v : h.visibility.pixels()) mx = std::max(mx, v);
  EXPECT_FLOAT_EQ(mx, 1.0f);
}

TEST(Bake, PaddingLeavesNoBlackTexelWithinTheMargin) {
  Scene s;
  s.meshes.push_back(uv_quad({-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}, {0.3f, 0.3f}, {0.55f, 0.6f}));
  s = prepared(std::move(s));
  const int n = 64, margin = 6;
  const TexelCoverage cov = compute_texel_coverage(s, n);
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  BakeResult r = bake_raytraced(rs, cov, {.samples = 16});  // open quad: exactly 1 on the charts
  pad(r.visibility, nearest_valid_texel(r.mask, margin));
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      int dmin = 1 << 30;  // Chebyshev distance to the nearest covered texel
      for (int yy = 0; yy < n; ++yy)
        for (int xx = 0; xx < n; ++xx)
          if (r.mask(xx, yy)) dmin = std::min(dmin, std::max(std::abs(xx - x), std::abs(yy - y)));
      if (dmin <= margin) EXPECT_GT(r.visibility(x, y), 0.5f) << x << "," << y;
      else EXPECT_EQ(r.visibility(x, y), 0.0f) << x << "," << y;
    }
}

// Two valid texels in a row, (2, 5) and (8, 5) of an 11 x 11 map: the rings reach each texel from
// the side whose source is nearer (the left one for x < 5, the right one for x > 5), a texel as near
// to both (x = 5) takes the first in index order, valid texels keep themselves, and a texel more
// rings away than the margin (Chebyshev distance) gets none.
TEST(Bake, PaddingTakesTheNearerSourceAndTheFirstOfEquals) {
  const int n = 11;
  Image<std::uint8_t> valid(n, n, std::uint8_t{0});
  valid(2, 5) = valid(8, 5) = 1;
  const std::int32_t left = 5 * n + 2, right = 5 * n + 8;
  const Image<std::int32_t> all = nearest_valid_texel(valid, 10);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) EXPECT_EQ(all(x, y), x <= 5 ? left : right) << x << "," << y;
  const Image<std::int32_t> near = nearest_valid_texel(valid, 2);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const int to_left = std::max(std::abs(x - 2), std::abs(y - 5)), to_right = std::max(std::abs(x - 8), std::abs(y - 5));
      EXPECT_EQ(near(x, y), to_left <= 2 ? left : to_right <= 2 ? right : -1) << x << "," << y;
    }
  EXPECT_EQ(nearest_valid_texel(valid, 0)(3, 5), -1);
  EXPECT_EQ(nearest_valid_texel(valid, 0)(8, 5), right);
}

TEST(Bake, PerVertexBothMethodsOnOpenQuadAndWall) {
  const Scene s = floor_and_wall(1.0f);
  const std::vector<float> h = bake_vertices_histogram(s, {.directions = 512, .resolution = 512});
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  const std::vector<float> r = bake_vertices_raytraced(rs, {.samples = 1024});
  ASSERT_EQ(h.size(), s.vertex_count());
  ASSERT_EQ(r.size(), s.vertex_count());
  // Floor vertices 0, 1 are at d = 1 from the wall: V = 0.854. (The crease vertices 2, 3 sit in the
  // wall's plane, where a point-sampled estimate depends on the offset: not a known answer.)
  for (int v : {0, 1}) {
    EXPECT_NEAR(r[v], wall_visibility(1, 1), 0.02);  // 1024 rays: std. error 0.011
    EXPECT_NEAR(h[v], wall_visibility(1, 1), 0.03);  // 512 directions, shadow-map bias
  }
}

TEST(Bake, PerVertexRaytracedIsTheSameAtAnyThreadCount) {
  // Vertices are traced in Morton order, in tiles spread over the threads; each vertex's samples
  // are keyed by its index, so neither the order nor the thread count may change a value.
  const Scene s = make_builtin_scene("default");
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  const RaytracedBakeParams params{.samples = 4, .max_distance = 0.5f};
  const std::vector<float> many = bake_vertices_raytraced(rs, params);
  std::vector<float> one;
  {
    tbb::global_control serial(tbb::global_control::max_allowed_parallelism, 1);
    one = bake_vertices_raytraced(rs, params);
  }
  ASSERT_EQ(many.size(), s.vertex_count());
  EXPECT_EQ(one, many);
  EXPECT_LT(*std::min_element(many.begin(), many.end()), 1.0f);  // something is occluded
}

TEST(Bake, MeshWithoutUvsIsAClearError) {
  const Scene s = make_builtin_scene("plane");
  try {
    compute_texel_coverage(s, 16);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--per-vertex"), std::string::npos) << e.what();
  }
}

TEST(Bake, OverlappingAndDegenerateUvsAreReported) {
  Scene s;
  s.meshes.push_back(uv_quad({-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}, {0, 0}, {1, 1}));
  s.meshes.push_back(uv_quad({-1, 1, 1}, {1, 1, 1}, {1, 1, -1}, {-1, 1, -1}, {0, 0}, {1, 1}));  // same UVs
  Mesh degenerate = uv_quad({-1, 2, 1}, {1, 2, 1}, {1, 2, -1}, {-1, 2, -1}, {0.5f, 0.5f}, {0.5f, 0.5f});
  s.meshes.push_back(degenerate);
  s = prepared(std::move(s));
  const TexelCoverage cov = compute_texel_coverage(s, 8);
  EXPECT_EQ(cov.overlapping_texels, 64u);
  EXPECT_EQ(cov.degenerate_uv_triangles, 2u);
  EXPECT_EQ(cov.warnings().size(), 2u);
}

TEST(Bake, BadParametersAreRejected) {
  EXPECT_THROW((HistogramParams{.directions = 0}.validate()), InputError);
  EXPECT_THROW((HistogramParams{.pixels_per_texel = 0}.validate()), InputError);
  EXPECT_THROW((HistogramParams{.point_size = 0.5f}.validate()), InputError);
  EXPECT_THROW((RaytracedBakeParams{.max_distance = -1.0f}.validate()), InputError);
  EXPECT_THROW((RaytracedBakeParams{.max_distance = kInfinity}.validate()), InputError);
  EXPECT_THROW((RaytracedBakeParams{.samples = 0}.validate()), InputError);
  EXPECT_THROW((RaytracedBakeParams{.denoise = -1.0f}.validate()), InputError);
  EXPECT_THROW((RaytracedBakeParams{.denoise = kMaxDenoiseSigma * 1.01f}.validate()), InputError);
  EXPECT_THROW((RaytracedBakeParams{.denoise = std::nanf("")}.validate()), InputError);
  const Scene s = make_builtin_scene("plane");
  EXPECT_THROW(compute_texel_coverage(s, 0), InputError);
}

}  // namespace
}  // namespace ao
