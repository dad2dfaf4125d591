// SPDX-License-Identifier: Apache-2.0
// The 4x4 depth-aware box filter of interleaved sampling (VAO and AT sec. 4.2).
#include "ao/methods/filters/interleave.h"

#include <gtest/gtest.h>

#include <array>

#include "ao/gbuffer/render_gbuffer.h"
#include "ao/scene/procedural.h"

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

// The entry points share one kernel whose RGB path spreads each pixel's depth test to its three
// lanes and whose planar path filters up to 4 planes with one test per pixel: each channel must
// come out as the float filter gives it alone, bit for bit (the same taps summed in the same
// order), on a real G-buffer of odd size (partial vectors, borders, background, depth edges).
TEST(Interleave, RgbAndPlanesGiveEachChannelTheFloatFiltersValues) {
  const Scene scene = make_builtin_scene("default");
  Camera c = *scene.preferred_view;
  c.width = 123, c.height = 77;
  const GBuffer g = render_gbuffer(RayScene(scene), c);
  std::array<Image<float>, 3> plane;
  Image<Vec3> rgb(c.width, c.height);
  for (int k = 0; k < 3; ++k) plane[k] = Image<float>(c.width, c.height);
  for (std::size_t i = 0; i < rgb.size(); ++i) {
    for (int k = 0; k < 3; ++k) plane[k][i] = static_cast<float>((i * (2654435761u + 40503u * k)) % 1000) / 1000.0f;
    rgb[i] = Vec3{plane[0][i], plane[1][i], plane[2][i]};
  }
  const float limit = 0.05f * scene.bounds().diagonal();
  const Image<Vec3> filtered_rgb = depth_aware_box_filter(rgb, g, limit);
  std::array<Image<float>, 3> filtered_planes = plane;
  std::array<Image<float>*, 3> planes{&filtered_planes[0], &filtered_planes[1], &filtered_planes[2]};
  depth_aware_box_filter_planes(planes, g, limit);
  std::size_t changed = 0;
  for (int k = 0; k < 3; ++k) {
    const Image<float> alone = depth_aware_box_filter(plane[k], g, limit);
    for (std::size_t i = 0; i < alone.size(); ++i) {
      const float v = k == 0 ? filtered_rgb[i].x : k == 1 ? filtered_rgb[i].y : filtered_rgb[i].z;
      ASSERT_EQ(v, alone[i]) << "RGB channel " << k << ", pixel " << i;
      ASSERT_EQ(filtered_planes[k][i], alone[i]) << "plane " << k << " of 3, pixel " << i;
      changed += alone[i] != plane[k][i];
    }
  }
  EXPECT_GT(changed, rgb.size()) << "the filter changed more than a third of the values (the test is not vacuous)";
}

}  // namespace
}  // namespace ao
