// The 4x4 depth-aware box filter of interleaved sampling (VAO and AT sec. 4.2).
#include "ao/methods/interleave.h"

#include <gtest/gtest.h>

namespace ao {
namespace {

// A w x h G-buffer covered everywhere, depth 1 on the left half and 5 on the right.
GBuffer two_depths(int w, int h) {
  Camera c;
  c.width = w;
  c.height = h;
  GBuffer g(c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      g.object_id(x, y) = 1;
      g.position(x, y) = {0, 0, x < w / 2 ? -1.0f : -5.0f};  // depth 1 or 5
    }
  return g;
}

TEST(Interleave, FilterAveragesTheSixteenPatternPositions) {
  const GBuffer g = two_depths(16, 16);
  Image<float> v(16, 16);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) v(x, y) = static_cast<float>((y % 4) * 4 + x % 4);  // pattern index
  const Image<float> f = depth_aware_box_filter(v, g, 0.5f);
  // Away from the borders and the depth edge every window holds each index 0..15 once: mean 7.5.
  EXPECT_FLOAT_EQ(f(4, 6), 7.5f);
  EXPECT_FLOAT_EQ(f(13, 9), 7.5f);
}

TEST(Interleave, FilterSkipsNeighboursAcrossADepthEdgeAndBackground) {
  GBuffer g = two_depths(16, 8);
  g.object_id(2, 2) = 0;  // background
  Image<float> v(16, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) v(x, y) = x < 8 ? 0.25f : 1.0f;
  v(2, 2) = 100.0f;  // background value must not leak
  const Image<float> f = depth_aware_box_filter(v, g, 0.5f);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x)
      if (g.covered(x, y)) {
        EXPECT_FLOAT_EQ(f(x, y), x < 8 ? 0.25f : 1.0f) << x << "," << y;
      }
  EXPECT_EQ(f(2, 2), 100.0f) << "uncovered pixels keep their value";
  // With a limit above the step the edge blurs.
  EXPECT_GT(depth_aware_box_filter(v, g, 10.0f)(7, 4), 0.25f);
}

TEST(Interleave, FilterWorksOnColour) {
  const GBuffer g = two_depths(8, 8);
  const Image<Vec3> v(8, 8, Vec3{0.1f, 0.2f, 0.3f});
  const Image<Vec3> f = depth_aware_box_filter(v, g, 0.5f);
  EXPECT_FLOAT_EQ(f(3, 3).y, 0.2f);
}

}  // namespace
}  // namespace ao
