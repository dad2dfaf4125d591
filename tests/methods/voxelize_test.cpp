// Parity voxelization against sets with exact answers: a voxel is solid exactly when its centre
// is inside a closed mesh, so an axis-aligned box gives an exact count.
#include "ao/methods/voxelize.h"

#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <cmath>
#include <random>

#include "ao/core/sampling.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/scene/procedural.h"

#include "support/scenes.h"

namespace ao {
namespace {

using test::scene_of;

// Voxel centres origin + (k + 0.5) * size strictly inside (lo, hi).
int centres_inside(float origin, float size, int n, float lo, float hi) {
  int c = 0;
  for (int k = 0; k < n; ++k) {
    const float x = origin + (static_cast<float>(k) + 0.5f) * size;
    c += x > lo && x < hi;
  }
  return c;
}

TEST(Voxelize, ClosedAxisAlignedBoxGivesExactVoxelCount) {
  // A second box widens the bounds so the first one's faces fall between voxel centres at
  // arbitrary offsets rather than on the grid's boundary.
  const Vec3 lo{-0.73f, 0.21f, -0.37f}, hi{0.91f, 1.33f, 0.58f};
  const Scene s = scene_of({make_box(lo, hi), make_box({-2, -1, -2}, {-1.5f, -0.5f, -1.5f})});
  for (int bits : {64, 96, 256}) {
    VoxelizeOptions o;
    o.columns = 64;
    o.depth_bits = bits;
    VoxelStats stats;
    const VoxelGrid g = voxelize_world(s, analyze_closure(s), o, &stats);
    const std::size_t expected =
        static_cast<std::size_t>(centres_inside(g.origin.x, g.voxel_size.x, g.nx, lo.x, hi.x)) *
            centres_inside(g.origin.z, g.voxel_size.y, g.ny, lo.z, hi.z) * centres_inside(g.origin.y, g.voxel_size.z, bits, lo.y, hi.y) +
        static_cast<std::size_t>(centres_inside(g.origin.x, g.voxel_size.x, g.nx, -2, -1.5f)) *
            centres_inside(g.origin.z, g.voxel_size.y, g.ny, -2, -1.5f) * centres_inside(g.origin.y, g.voxel_size.z, bits, -1, -0.5f);
    EXPECT_EQ(g.count_set(), expected) << bits << " bits";
    EXPECT_EQ(stats.odd_columns, 0u);
    EXPECT_EQ(stats.set_voxels, expected);
  }
}

TEST(Voxelize, SphereVolumeMatchesFourThirdsPiRCubed) {
  const Scene s = scene_of({make_sphere({0.1f, 0.2f, -0.3f}, 1.0f, 128, 64)});
  VoxelizeOptions o;
  o.columns = 128;
  o.depth_bits = 128;
  VoxelStats stats;
  const VoxelGrid g = voxelize_world(s, analyze_closure(s), o, &stats);
  const double voxel = double(g.voxel_size.x) * g.voxel_size.y * g.voxel_size.z;
  const double volume = static_cast<double>(g.count_set()) * voxel;
  // Tolerance 1%: the 128 x 64 UV sphere is 0.1% smaller than the true sphere, and centre sampling
  // misclassifies part of the ~4 pi r^2 * 1.6e-2 = 0.2 shell of boundary voxels, with errors of
  // both signs that cancel to well under a tenth of it.
  EXPECT_NEAR(volume, 4.0 / 3.0 * M_PI, 0.01 * 4.0 / 3.0 * M_PI);
  EXPECT_EQ(stats.odd_columns, 0u);
}

TEST(Voxelize, BitCountOverRangesCrossingWordsMatchesNaiveCount) {
  std::mt19937_64 rng(5);
  std::uint64_t col[4] = {};
  for (auto& w : col) w = rng();
  for (int k0 = -3; k0 <= 259; k0 += 1)
    for (int k1 = k0; k1 <= 259; k1 += 7) {
      int naive = 0;
      for (int k = std::max(k0, 0); k < std::min(k1, 256); ++k) naive += (col[k / 64] >> (k % 64)) & 1;
      ASSERT_EQ(count_bits(col, 4, k0, k1), naive) << k0 << ".." << k1;
      ASSERT_EQ(any_bits(col, 4, k0, k1), naive > 0) << k0 << ".." << k1;
    }
}

TEST(Voxelize, ClosureCountsBoundaryEdgesByPosition) {
  const Scene s = scene_of({make_box({0, 0, 0}, {1, 1, 1}), make_quad({0, 0, 1}, {1, 0, 1}, {1, 0, 0}, {0, 0, 0}), make_sphere({3, 0, 0}, 1)});
  const auto c = analyze_closure(s);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_TRUE(c[0].closed()) << "make_box repeats corners per face; welding by position closes it";
  EXPECT_EQ(c[1].boundary_edges, 4u);
  EXPECT_TRUE(c[2].closed());
}

// A closed mesh with a hole (a scanned statue) is not an open surface: slabs R_max thick behind
// every face would fill its thin parts and the space in front of them (seen on ChineseDragon-10kv,
// cone RMSE 0.53 with slabs, 0.054 with parity). A ground quad is.
TEST(Voxelize, OnlyOpenSurfacesBecomeSlabs) {
  Mesh holed = make_sphere({0, 0, 0}, 1.0f, 32, 16);
  holed.indices.resize(holed.indices.size() - 3);  // one triangle missing: three boundary edges
  const Scene s = scene_of({holed, make_quad({0, 0, 1}, {1, 0, 1}, {1, 0, 0}, {0, 0, 0})});
  const auto c = analyze_closure(s);
  EXPECT_EQ(c[0].boundary_edges, 3u);
  EXPECT_FALSE(c[0].closed());
  EXPECT_FALSE(c[0].open_surface());
  EXPECT_TRUE(c[1].open_surface());
}

TEST(Voxelize, OpenMeshParityIsReportedAndSlabsCloseIt) {
  const Scene s = make_builtin_scene("plane");
  const auto closure = analyze_closure(s);
  VoxelizeOptions o;
  o.columns = 32;
  o.depth_bits = 64;
  o.open_meshes = OpenMeshes::Parity;
  VoxelStats parity;
  const VoxelGrid pg = voxelize_world(s, closure, o, &parity);
  // Every column whose centre is over the 40 x 40 plane crosses it once and ends odd.
  const std::size_t over = static_cast<std::size_t>(centres_inside(pg.origin.x, pg.voxel_size.x, pg.nx, -20, 20)) *
                           centres_inside(pg.origin.z, pg.voxel_size.y, pg.ny, -20, 20);
  EXPECT_GT(over, 0u);
  EXPECT_EQ(parity.odd_columns, over);
  EXPECT_EQ(parity.open_meshes, 1u);
  EXPECT_EQ(parity.boundary_edges, 4u);
  o.open_meshes = OpenMeshes::Slab;
  o.slab_thickness = 0.5f;
  VoxelStats slab;
  const VoxelGrid g = voxelize_world(s, closure, o, &slab);
  EXPECT_EQ(slab.odd_columns, 0u);
  // The slab lies below the plane: every set voxel centre is in [-0.5, 0].
  for (int k = 0; k < g.depth_bits; ++k) {
    const float y = g.origin.y + (k + 0.5f) * g.voxel_size.z;
    EXPECT_EQ(g.voxel(7, 9, k), y > -0.5f && y < 0.0f) << "k = " << k << ", y = " << y;
  }
}

TEST(Voxelize, EyeGridIsSolidInsideABoxAndEmptyInFront) {
  const Scene s = scene_of({make_box({-1, -1, -1}, {1, 1, 1})});
  const RayScene rs(s);
  Camera cam;
  cam.eye = {0, 0, 5};
  cam.target = {0, 0, 0};
  cam.width = 64;
  cam.height = 48;
  const GBuffer gb = render_gbuffer(rs, cam);
  VoxelizeOptions o;
  o.columns = 32;
  o.depth_bits = 128;
  VoxelStats stats;
  const VoxelGrid g = voxelize_eye(s, analyze_closure(s), gb, o, &stats);
  EXPECT_EQ(stats.odd_columns, 0u);
  const int i = g.nx / 2, j = g.ny / 2;
  const std::size_t c = static_cast<std::size_t>(j) * g.nx + i;
  // eq. 2: z_nearest is the box's front face at depth 4; the box spans depths [4, 6].
  EXPECT_NEAR(g.z_near[c], 4.0f, 1e-3f);
  for (int k = 0; k < g.depth_bits; ++k) {
    const float z = g.z_near[c] + (k + 0.5f) / g.voxels_per_unit[c];
    if (std::abs(z - 6.0f) < 1.0f / g.voxels_per_unit[c]) continue;  // the back face's voxel
    EXPECT_EQ(g.voxel(i, j, k), z < 6.0f) << "k = " << k << ", depth " << z;
  }
}

// The window masks (voxelize.h) against their definition, brute force: bit ck of window w at
// (ci, cj) is set exactly when a voxel of a cell (ci'..., ck) with ci <= ci' <= ci + w,
// cj <= cj' <= cj + w is solid. Grid sizes that are not multiples of the cell clip the windows.
TEST(Voxelize, WindowMasksAreTheOrOfTheirCells) {
  const Scene s = scene_of({make_sphere({0.1f, 0.2f, -0.3f}, 1.0f, 32, 16), make_box({-2, -1, -2}, {-1.5f, 0.5f, 1.5f})});
  for (int columns : {61, 64}) {
    VoxelizeOptions o;
    o.columns = columns;
    o.depth_bits = 256;  // 2 voxels per mask bit
    const VoxelGrid g = voxelize_world(s, analyze_closure(s), o);
    ASSERT_EQ(g.cell_bits, 4);
    constexpr int C = VoxelGrid::kCellXY;
    for (int cj = 0; cj < g.dny; ++cj)
      for (int ci = 0; ci < g.dnx; ++ci)
        for (int w = 0; w <= VoxelGrid::kWindowCap; w += 3) {
          std::uint64_t expected = 0;
          for (int j = cj * C; j < std::min(g.ny, (cj + w + 1) * C); ++j)
            for (int i = ci * C; i < std::min(g.nx, (ci + w + 1) * C); ++i)
              for (int k = 0; k < g.depth_bits; ++k)
                if (g.voxel(i, j, k)) expected |= std::uint64_t{1} << (k / g.cell_bits);
          ASSERT_EQ(g.window_mask(w, ci, cj), expected) << columns << " columns, cell " << ci << ", " << cj << ", w " << w;
        }
  }
}

TEST(Voxelize, SameGridAtOneAndTwoThreads) {
  const Scene s = make_builtin_scene("default");
  const auto closure = analyze_closure(s);
  VoxelizeOptions o;
  o.columns = 128;
  o.depth_bits = 96;
  VoxelGrid a, b;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    a = voxelize_world(s, closure, o);
  }
  {
    tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
    b = voxelize_world(s, closure, o);
  }
  EXPECT_EQ(a.bits, b.bits);
}

TEST(Voxelize, RejectsBadOptions) {
  const Scene s = make_builtin_scene("plane");
  const auto closure = analyze_closure(s);
  for (int bits : {0, 33, 31, 2000, 1056}) {
    VoxelizeOptions o;
    o.depth_bits = bits;
    EXPECT_THROW(voxelize_world(s, closure, o), InputError) << bits;
  }
  VoxelizeOptions o;
  o.columns = 4;
  EXPECT_THROW(voxelize_world(s, closure, o), InputError);
}

}  // namespace
}  // namespace ao
