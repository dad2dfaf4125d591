// SPDX-License-Identifier: Apache-2.0
// GBuffer's derived channels: linear depth is -position.z and coverage is object_id != 0, per
// pixel and as the planes kernels and metrics read.
#include "ao/core/gbuffer.h"
#include "ao/simd/depth_plane.h"

#include <gtest/gtest.h>

namespace ao {
namespace {

// A 3 x 2 G-buffer: pixel (x, y) covered at depth 1 + x + 3 y unless it is (1, 0).
GBuffer small_gbuffer() {
  Camera c;
  c.width = 3, c.height = 2;
  GBuffer g(c);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) {
      if (x == 1 && y == 0) continue;
      g.position(x, y) = c.camera_direction(x + 0.5f, y + 0.5f) * static_cast<float>(1 + x + 3 * y);
      g.object_id(x, y) = 7;
    }
  return g;
}

TEST(GBuffer, NewBufferIsAllBackground) {
  Camera c;
  c.width = 4, c.height = 2;
  const GBuffer g(c);
  for (std::size_t i = 0; i < 8; ++i) {
    EXPECT_FALSE(g.covered(i));
    EXPECT_EQ(g.depth(i), kInfinity);
  }
}

TEST(GBuffer, DepthIsMinusPositionZWhereCoveredAndInfinityElsewhere) {
  const GBuffer g = small_gbuffer();
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * 3 + x;
      const bool covered = !(x == 1 && y == 0);
      EXPECT_EQ(g.covered(x, y), covered);
      EXPECT_EQ(g.covered(i), covered);
      // camera_direction has z = -1, so the depth is the factor exactly.
      const float want = covered ? static_cast<float>(1 + x + 3 * y) : kInfinity;
      EXPECT_EQ(g.depth(x, y), want) << x << ", " << y;
      EXPECT_EQ(g.depth(i), want);
    }
}

TEST(GBuffer, DepthPlaneAndCoverageMaskHoldEveryPixel) {
  const GBuffer g = small_gbuffer();
  Image<float> plane(1, 1, -1.0f);  // reused storage of another size
  depth_plane(g, plane);
  const Image<std::uint8_t> mask = coverage_mask(g);
  ASSERT_EQ(plane.width(), 3);
  ASSERT_EQ(plane.height(), 2);
  ASSERT_EQ(mask.width(), 3);
  ASSERT_EQ(mask.height(), 2);
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(plane[i], g.depth(i)) << i;
    EXPECT_EQ(mask[i], g.covered(i) ? 1 : 0) << i;
  }
  EXPECT_EQ(depth_plane(g)[1], kInfinity);
}

// A plane wider than one 64-pixel task, so that the parallel fill's tiles all land where they belong.
TEST(GBuffer, DepthPlaneOfALargeBufferMatchesThePixels) {
  Camera c;
  c.width = 150, c.height = 40;
  GBuffer g(c);
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x)
      if ((x + y) % 5 != 0) g.position(x, y) = {0.0f, 0.0f, -static_cast<float>(x + 1000 * y + 1)}, g.object_id(x, y) = 1;
  const Image<float> plane = depth_plane(g);
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) ASSERT_EQ(plane(x, y), (x + y) % 5 != 0 ? static_cast<float>(x + 1000 * y + 1) : kInfinity) << x << ", " << y;
}

}  // namespace
}  // namespace ao
