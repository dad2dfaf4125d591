// SPDX-License-Identifier: Apache-2.0
// Parity voxelization against sets with exact answers: a voxel is solid exactly when its centre
// is inside a closed mesh, so an axis-aligned box gives an exact count.
#include "ao/methods/cone/voxelize.h"

#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <cmath>
#include <random>

#include "ao/core/sampling.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/methods/cone/winding_number.h"
#include "ao/scene/procedural.h"

#include "support/open_sheets.h"
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

// Options of a small grid: columns x columns columns of depth_bits voxels, slabs `slab` thick.
VoxelizeOptions grid_options(int columns, int depth_bits, float slab = 0.0f) {
  VoxelizeOptions o;
  o.columns = columns;
  o.depth_bits = depth_bits;
  o.slab_thickness = slab;
  return o;
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

// A closed mesh with a hole (a scanned statue) is not a sheet but a solid with holes (its
// enclosure is about 1): slabs R_max thick behind every face would fill its thin parts and the
// space in front of them (seen on ChineseDragon-10kv, cone RMSE 0.53 with slabs, 0.054 with
// parity). A ground quad is a sheet.
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

// What each open mesh is taken for, by its enclosure (mesh_closure.h, kSolidEnclosure): sheets (a flat
// quad, a bent sheet with holes) and meshes that wrap around a volume (an open container, a sphere
// with a hole), whatever way their triangles face.
TEST(Voxelize, OpenMeshesAreClassifiedByTheirWindingNumber) {
  Mesh holed = make_sphere({0, 0, 0}, 1.0f, 32, 16);
  holed.indices.resize(holed.indices.size() - 3);
  const Mesh inverted = test::turned_over(holed);
  const Scene s = scene_of({make_quad({0, 0, 1}, {1, 0, 1}, {1, 0, 0}, {0, 0, 0}), test::make_holed_arch(), test::make_bowl(), test::make_open_box(), holed,
                            inverted, make_box({3, 3, 3}, {4, 4, 4})});
  const auto c = analyze_closure(s);
  const MeshKind expected[] = {MeshKind::Sheet,          MeshKind::Sheet,          MeshKind::SolidWithHoles, MeshKind::SolidWithHoles,
                               MeshKind::SolidWithHoles, MeshKind::SolidWithHoles, MeshKind::Closed};
  for (std::size_t m = 0; m < c.size(); ++m) EXPECT_EQ(c[m].kind, expected[m]) << "mesh " << m << ", enclosure " << c[m].enclosure;
  EXPECT_TRUE(c[0].flat);
  EXPECT_NEAR(c[0].enclosure, 0.0f, 1e-6f);
  EXPECT_FALSE(c[1].flat);
  // A sphere missing one triangle wraps around its inside all but entirely: its hole spans far
  // less than kSmallHoles of its area, so its enclosure is 1 minus that fraction and its
  // orientation the sign of its volume.
  EXPECT_GT(c[4].enclosure, 0.95f);
  EXPECT_EQ(c[4].orientation, 1);
  EXPECT_EQ(c[5].orientation, -1);
  EXPECT_NEAR(c[4].enclosure, c[5].enclosure, 1e-4f);
}

// A closed mesh's grid is its parity, whatever is done with open meshes: each voxel is solid
// exactly when an odd number of triangles cross its column below its centre (counted here on
// their own, in double precision, away from ties on an edge or at a centre).
TEST(Voxelize, ClosedMeshGridIsTheParityOfEveryColumn) {
  const Scene s = scene_of({make_sphere({0.13f, 0.41f, -0.27f}, 0.9f, 40, 20), make_torus({1.1f, 0.2f, 0.9f}, 0.6f, 0.2f, 32, 12),
                            make_box({-1.7f, -0.3f, 0.6f}, {-0.9f, 0.9f, 1.3f}, {}, 23.0f)});
  const auto closure = analyze_closure(s);
  VoxelizeOptions o = grid_options(64, 96);
  const VoxelGrid g = voxelize_world(s, closure, o);
  std::size_t checked = 0;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const double x = g.origin.x + (i + 0.5) * g.voxel_size.x, z = g.origin.z + (j + 0.5) * g.voxel_size.y;
      std::vector<double> ys;  // crossings of the column's line
      bool tie = false;
      for (const Mesh& m : s.meshes)
        for (std::size_t t = 0; t < m.triangle_count(); ++t) {
          const Vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]], c = m.positions[m.indices[3 * t + 2]];
          const double d = (double(b.x) - a.x) * (double(c.z) - a.z) - (double(c.x) - a.x) * (double(b.z) - a.z);
          if (d == 0) continue;
          const double u = ((double(b.x) - x) * (double(c.z) - z) - (double(c.x) - x) * (double(b.z) - z)) / d;
          const double v = ((double(c.x) - x) * (double(a.z) - z) - (double(a.x) - x) * (double(c.z) - z)) / d;
          const double w = 1 - u - v;
          if (std::min({u, v, w}) < -1e-9) continue;
          if (std::min({u, v, w}) < 1e-9) tie = true;
          ys.push_back(u * a.y + v * b.y + w * c.y);
        }
      if (tie) continue;
      for (int k = 0; k < g.depth_bits; ++k) {
        const double y = g.origin.y + (k + 0.5) * g.voxel_size.z;
        int below = 0;
        bool near = false;
        for (double c : ys) below += c < y, near = near || std::abs(c - y) < 1e-6;
        if (near) continue;
        ASSERT_EQ(g.voxel(i, j, k), below % 2 == 1) << "column " << i << ", " << j << ", voxel " << k;
        ++checked;
      }
    }
  EXPECT_GT(checked, 300000u);
  for (OpenMeshes mode : {OpenMeshes::Slab, OpenMeshes::Parity}) {
    o.open_meshes = mode;
    EXPECT_EQ(voxelize_world(s, closure, o).bits, g.bits);
  }
  o.open_meshes = OpenMeshes::Winding;
  const std::vector<std::uint8_t> back(3, 1);
  EXPECT_EQ(voxelize_world(s, closure, o, nullptr, back).bits, g.bits) << "closed meshes have no back side";
}

// A sphere cut along a wavy line (a hole that is not flat): its grid is the solid where its
// winding number exceeds 1/2, also in the pocket between the fan that closes the hole and the
// surface w = 1/2 that spans it (where parity with the fan alone is wrong). Checked at every voxel
// centre whose w is not within 0.02 of 1/2 (the hierarchy's error is 0.005 at worst,
// winding_number_test.cpp), for both orientations of the triangles.
TEST(Voxelize, SolidWithAHoleThatIsNotFlatIsItsWindingNumberSolid) {
  // Off the grid's axes and diagonals (a column along a meridian edge would be a tie of parity).
  const Mesh cut = test::cut(make_sphere({0.0137f, 0.0071f, -0.0213f}, 1.0f, 64, 32),
                             [](Vec3 c) { return c.y < 0.45f + 0.4f * std::sin(2.0f * std::atan2(c.z, c.x)); });
  const Mesh turned = test::turned_over(cut);
  for (const Mesh& m : {cut, turned}) {
    const Scene s = scene_of({m});
    const auto closure = analyze_closure(s);
    ASSERT_TRUE(closure[0].holed());
    const VoxelizeOptions o = grid_options(40, 64);
    VoxelStats stats;
    const VoxelGrid g = voxelize_world(s, closure, o, &stats);
    EXPECT_GT(stats.winding_voxels_changed, 0u) << "the pocket holds voxel centres";
    const WindingNumber w(m.positions, m.indices);
    std::size_t checked = 0;
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i)
        for (int k = 0; k < g.depth_bits; ++k) {
          const Vec3 p{g.origin.x + (i + 0.5f) * g.voxel_size.x, g.origin.y + (k + 0.5f) * g.voxel_size.z, g.origin.z + (j + 0.5f) * g.voxel_size.y};
          const double wp = closure[0].orientation * w(p);
          if (std::abs(wp - 0.5) < 0.02) continue;
          ASSERT_EQ(g.voxel(i, j, k), wp > 0.5) << "voxel " << i << ", " << j << ", " << k << ": w = " << wp;
          ++checked;
        }
    EXPECT_GT(checked, 90000u);
  }
}

// A sheet is a slab on the far side from the points a grid is traced for: below a quad facing up
// for points above it, above it for points below it (its back side).
TEST(Voxelize, SheetSlabLiesOnTheFarSideFromThePoints) {
  const Scene s = scene_of({make_quad({-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1})});
  const auto closure = analyze_closure(s);
  const VoxelizeOptions o = grid_options(32, 64, 0.5f);
  for (std::uint8_t side : {0, 1}) {
    const std::vector<std::uint8_t> back{side};
    VoxelStats stats;
    const VoxelGrid g = voxelize_world(s, closure, o, &stats, back);
    EXPECT_EQ(stats.back_objects, side);
    for (int k = 0; k < g.depth_bits; ++k) {
      const float y = g.origin.y + (k + 0.5f) * g.voxel_size.z;
      const bool in_slab = side ? y > 0.0f && y < 0.5f : y > -0.5f && y < 0.0f;
      EXPECT_EQ(g.voxel(16, 16, k), in_slab) << "side " << int(side) << ", y = " << y;
    }
  }
}

// The world grid puts the scene's ground (its largest area facing up, here above the scene's
// lowest point) a hundredth of a voxel above a boundary between voxels and between coarse cells
// (world_grid_layout), so that it is solid up to its height and its voxel above it is air, whatever the scene's height;
// the top keeps a voxel of margin above the bounds.
TEST(Voxelize, GroundLiesOnAVoxelBoundary) {
  for (float height : {0.37f, 1.0f, 2.9f}) {
    // A box standing on the ground and a small plate below it (the scene's lowest point).
    const Scene s = scene_of({make_quad({-2, 0.1f, 2}, {2, 0.1f, 2}, {2, 0.1f, -2}, {-2, 0.1f, -2}), make_box({-0.5f, 0.1f, -0.5f}, {0.5f, 0.1f + height, 0.5f}),
                              make_quad({1, -0.23f, 1.5f}, {1.3f, -0.23f, 1.5f}, {1.3f, -0.23f, 1.2f}, {1, -0.23f, 1.2f})});
    const VoxelGrid g = voxelize_world(s, analyze_closure(s), grid_options(64, 128, 0.3f));
    const double k = (0.1 - double(g.origin.y)) / g.voxel_size.z;
    EXPECT_NEAR(k - std::floor(k), 0.01, 1e-3) << height;  // a hundredth of a voxel above a boundary
    const int kg = static_cast<int>(std::floor(k));
    EXPECT_EQ(kg % g.cell_bits, 0) << height;
    // A column over the ground beside the box (x, z = -1.7): the ground's voxel below the surface is
    // solid (its slab), the one above is air.
    EXPECT_TRUE(g.voxel(8, 8, kg - 1)) << height;
    EXPECT_FALSE(g.voxel(8, 8, kg)) << height;
    EXPECT_GE(g.origin.y + g.depth_bits * g.voxel_size.z, 0.1f + height + g.voxel_size.z * 0.99f) << height;
  }
}

// Two walls of one open mesh meet at a corner, facing out of it; their prisms (behind them, 0.5
// thick) overlap in the corner, which is as solid as the rest of each: the union, not the parity,
// of the prisms.
TEST(Voxelize, WallPrismsAreUnitedWhereWallsMeet) {
  Mesh walls = make_quad({0, 1, 0}, {2, 1, 0}, {2, 0, 0}, {0, 0, 0});         // x in [0, 2] at z = 0, facing -z
  append_mesh(walls, make_quad({0, 1, 2}, {0, 1, 0}, {0, 0, 0}, {0, 0, 2}));  // z in [0, 2] at x = 0, facing -x
  const Scene s = scene_of({walls});
  const auto closure = analyze_closure(s);
  ASSERT_TRUE(closure[0].open_surface());
  const VoxelizeOptions o = grid_options(64, 64, 0.5f);
  const VoxelGrid g = voxelize_world(s, closure, o);
  const auto solid = [&](float x, float y, float z) {
    return g.voxel(static_cast<int>((x - g.origin.x) / g.voxel_size.x), static_cast<int>((z - g.origin.z) / g.voxel_size.y),
                   static_cast<int>((y - g.origin.y) / g.voxel_size.z));
  };
  EXPECT_TRUE(solid(1.0f, 0.5f, 0.25f)) << "behind the first wall";
  EXPECT_TRUE(solid(0.25f, 0.5f, 1.0f)) << "behind the second wall";
  EXPECT_TRUE(solid(0.25f, 0.5f, 0.25f)) << "behind both: the corner";
  EXPECT_FALSE(solid(1.0f, 0.5f, 1.0f)) << "beyond both prisms";
  EXPECT_FALSE(solid(1.0f, 0.5f, -0.25f)) << "in front of the first wall";
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
  // Back-side flags are one per object of the scene.
  const std::vector<std::uint8_t> two_flags{0, 1};
  EXPECT_THROW(voxelize_world(s, closure, VoxelizeOptions{}, nullptr, two_flags), InputError);
  EXPECT_THROW(voxelize_world(s, std::span<const MeshClosure>(), VoxelizeOptions{}), InputError);
}

}  // namespace
}  // namespace ao
