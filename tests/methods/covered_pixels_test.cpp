// SPDX-License-Identifier: Apache-2.0
// The screen-space methods' row loader (simd::load_covered_pixels): the covered pixels of a row
// segment, compacted in order, with their position, normal and rotation, and the padding entries
// up to a whole vector a harmless point. Checked against a plain loop over the pixels on coverage
// patterns that take every path of the loader (vectors wholly, partly and not covered, segments
// that start off a vector's and a rotation's boundary, a tail shorter than a vector), on each
// SIMD target (the suite runs once per target, tests/CMakeLists.txt).
#include <gtest/gtest.h>

#include <cstdint>
#include <random>

#include "ao/core/gbuffer.h"
#include "ao/simd/aligned_internal.h"
#include "ao/methods/screen_space_kernel_internal.h"

namespace ao {
namespace {

constexpr int kWidth = 150, kHeight = 8;

// Coverage by row: 0 all covered, 1 none, 2 alternate pixels, 3 random (half), 4 runs of 1 to 40
// pixels covered or not, 5 all but one pixel in each 16, 6 and 7 random (a tenth and nine tenths).
GBuffer pattern_gbuffer() {
  Camera cam;
  cam.width = kWidth, cam.height = kHeight;
  GBuffer g(cam);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int y = 0; y < kHeight; ++y) {
    int run = 0;
    bool on = true;
    for (int x = 0; x < kWidth; ++x) {
      bool covered = true;
      switch (y) {
        case 0: covered = true; break;
        case 1: covered = false; break;
        case 2: covered = x % 2 == 0; break;
        case 3: covered = u(rng) < 0.5f; break;
        case 4:
          if (run == 0) run = 1 + static_cast<int>(rng() % 40), on = !on;
          covered = on, --run;
          break;
        case 5: covered = x % 16 != 7; break;
        case 6: covered = u(rng) < 0.1f; break;
        default: covered = u(rng) < 0.9f; break;
      }
      if (!covered) continue;
      g.object_id(x, y) = 1 + static_cast<std::uint32_t>(x % 3);
      g.position(x, y) = {0.01f * static_cast<float>(x) - 0.5f, 0.02f * static_cast<float>(y), -1.0f - 0.003f * static_cast<float>(x + y)};
      g.normal(x, y) = normalize(Vec3{0.1f * static_cast<float>(x % 5), 0.2f, 1.0f + 0.01f * static_cast<float>(y)});
    }
  }
  return g;
}

TEST(CoveredPixels, RowLoaderCompactsEveryCoveredPixelInOrder) {
  const GBuffer g = pattern_gbuffer();
  simd::Rotations16 rot;
  for (int i = 0; i < 16; ++i) rot.c[i] = 0.1f + static_cast<float>(i), rot.s[i] = -0.5f - static_cast<float>(i);
  simd::CoveredPixels row;
  const int segments[][2] = {{0, kWidth}, {0, 64}, {3, 67}, {5, 6}, {17, 33}, {64, 128}, {101, kWidth}, {149, kWidth}, {1, 16}, {30, 47}};
  for (int y = 0; y < kHeight; ++y)
    for (const auto& seg : segments) {
      const int x0 = seg[0], x1 = seg[1];
      simd::load_covered_pixels(row, g, y, x0, x1, rot, 0.25f, false);
      SCOPED_TRACE("row " + std::to_string(y) + ", segment [" + std::to_string(x0) + ", " + std::to_string(x1) + ")");
      int k = 0;
      for (int x = x0; x < x1; ++x) {
        if (!g.covered(x, y)) continue;
        ASSERT_LT(k, row.count);
        const auto e = static_cast<std::size_t>(k);
        EXPECT_EQ(row.index[e], x - x0);
        const Vec3 p = g.position(x, y), n = g.normal(x, y);
        EXPECT_TRUE(row.px[e] == p.x && row.py[e] == p.y && row.pz[e] == p.z) << "position of x = " << x;
        EXPECT_TRUE(row.nx[e] == n.x && row.ny[e] == n.y && row.nz[e] == n.z) << "normal of x = " << x;
        // The 4x4 interleaving pattern: rotation (y mod 4) * 4 + (x mod 4).
        EXPECT_EQ(row.rc[e], rot.c[(y & 3) * 4 + (x & 3)]);
        EXPECT_EQ(row.rs[e], rot.s[(y & 3) * 4 + (x & 3)]);
        EXPECT_EQ(row.bias[e], 0.25f);
        ++k;
      }
      EXPECT_EQ(row.count, k) << "exactly the covered pixels";
      for (int e = row.count; e < simd::padded(row.count); ++e) {
        const auto i = static_cast<std::size_t>(e);
        EXPECT_EQ(row.index[i], 0);
        EXPECT_TRUE(row.px[i] == 0.0f && row.py[i] == 0.0f && row.pz[i] == -1.0f) << "padding entry " << e << ": one unit in front";
        EXPECT_TRUE(row.nx[i] == 0.0f && row.ny[i] == 0.0f && row.nz[i] == 1.0f) << "padding entry " << e << ": facing the camera";
        EXPECT_TRUE(row.rc[i] == 1.0f && row.rs[i] == 0.0f) << "padding entry " << e << ": no rotation";
      }
    }
}

}  // namespace
}  // namespace ao
