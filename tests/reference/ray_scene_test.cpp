// SPDX-License-Identifier: Apache-2.0
// RayScene's build settings change how the BVH is built, never what a ray hits: every quality,
// compact or not, with the mesh arrays shared or copied, gives the same G-buffer depths.
#include "ao/reference/ray_scene.h"

#include <gtest/gtest.h>

#include <cmath>

#include "ao/core/camera.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/scene/procedural.h"

namespace ao {
namespace {

TEST(RayScene, EveryBuildSettingHitsTheSameSurfaces) {
  Scene scene = make_builtin_scene("default");
  const Camera cam = frame_bounds(scene.bounds(), {1, 0.8f, 1.2f}, 45.0f, 96, 64);
  const RayScene high(scene, {BvhQuality::High, false});
  EXPECT_EQ(high.quality(), BvhQuality::High);
  EXPECT_FALSE(high.compact());
  const GBuffer want = render_gbuffer(high, cam);
  // Without the spare capacity the arrays are copied instead of shared.
  Scene tight = scene;
  for (Mesh& m : tight.meshes) m.positions.shrink_to_fit();
  for (const auto& [s, options] : {std::pair<const Scene*, BvhOptions>{&scene, {BvhQuality::Medium, true}},
                                   {&scene, {BvhQuality::Low, false}},
                                   {&scene, {BvhQuality::High, true}},
                                   {&tight, {BvhQuality::Medium, true}}}) {
    const RayScene rs(*s, options);
    EXPECT_EQ(rs.quality(), *options.quality);
    EXPECT_EQ(rs.compact(), *options.compact);
    const GBuffer got = render_gbuffer(rs, cam);
    int covered = 0;
    for (int y = 0; y < cam.height; ++y)
      for (int x = 0; x < cam.width; ++x) {
        ASSERT_EQ(got.covered(x, y), want.covered(x, y)) << x << "," << y;
        if (!want.covered(x, y)) continue;
        ++covered;
        // The same triangle intersected the same way; the BVH only changes the order of tests.
        EXPECT_NEAR(got.depth(x, y), want.depth(x, y), 1e-5f * want.depth(x, y)) << x << "," << y;
        EXPECT_EQ(got.object_id(x, y), want.object_id(x, y)) << x << "," << y;
      }
    EXPECT_GT(covered, cam.width * cam.height / 8);  // the scene fills enough of the view to test
  }
}

TEST(RayScene, SmallScenesGetTheHighQualityBvhByDefault) {
  const Scene scene = make_builtin_scene("default");
  ASSERT_LT(scene.triangle_count(), kCompactBvhTriangles);
  const RayScene rs(scene);
  EXPECT_EQ(rs.quality(), BvhQuality::High);
  EXPECT_FALSE(rs.compact());
}

}  // namespace
}  // namespace ao
