// SPDX-License-Identifier: Apache-2.0
#include "ao/core/camera.h"

#include <gtest/gtest.h>

#include "ao/core/error.h"

namespace ao {
namespace {

TEST(Camera, ProjectInvertsCameraDirection) {
  Camera c;
  c.width = 640;
  c.height = 480;
  c.vertical_fov_deg = 60;
  for (float px : {0.5f, 100.25f, 639.5f})
    for (float py : {0.5f, 240.0f, 479.5f}) {
      const Vec3 d = c.camera_direction(px, py) * 3.0f;
      const Vec2 p = c.project(d);
      EXPECT_NEAR(p.x, px, 1e-3f);
      EXPECT_NEAR(p.y, py, 1e-3f);
    }
}

TEST(Camera, LooksDownMinusZWithYUp) {
  Camera c;
  c.eye = {0, 0, 5};
  c.target = {0, 0, 0};
  EXPECT_NEAR(length(c.world_to_camera_point({0, 0, 0}) - Vec3{0, 0, -5}), 0.0f, 1e-6f);
  // A point above the target is above the image centre: smaller row index.
  EXPECT_LT(c.project(c.world_to_camera_point({0, 1, 0})).y, c.height / 2.0f);
  // A point to the right (+x) is right of the centre.
  EXPECT_GT(c.project(c.world_to_camera_point({1, 0, 0})).x, c.width / 2.0f);
  const Vec3 p{1, 2, 3};
  EXPECT_NEAR(length(c.camera_to_world_point(c.world_to_camera_point(p)) - p), 0.0f, 1e-5f);
}

TEST(Camera, FramingKeepsTheBoundsInView) {
  Bounds3 b;
  b.extend(Vec3{-1, 0, -2});
  b.extend(Vec3{3, 1, 2});
  const Camera c = frame_bounds(b, {1, 1, 1}, 40, 320, 200);
  for (int i = 0; i < 8; ++i) {
    const Vec3 corner{i & 1 ? b.hi.x : b.lo.x, i & 2 ? b.hi.y : b.lo.y, i & 4 ? b.hi.z : b.lo.z};
    const Vec3 pc = c.world_to_camera_point(corner);
    ASSERT_LT(pc.z, 0.0f);
    const Vec2 p = c.project(pc);
    EXPECT_GE(p.x, 0.0f);
    EXPECT_LE(p.x, 320.0f);
    EXPECT_GE(p.y, 0.0f);
    EXPECT_LE(p.y, 200.0f);
  }
}

TEST(Camera, RejectsDegenerateSetups) {
  Camera c;
  c.target = c.eye;
  EXPECT_THROW(c.validate(), InputError);
  c = Camera{};
  c.up = c.target - c.eye;
  EXPECT_THROW(c.validate(), InputError);
  c = Camera{};
  c.vertical_fov_deg = 180;
  EXPECT_THROW(c.validate(), InputError);
  c = Camera{};
  c.width = 0;
  EXPECT_THROW(c.validate(), InputError);
  c = Camera{};
  c.width = 1 << 20;
  EXPECT_THROW(c.validate(), InputError);
  c = Camera{};
  c.eye.x = std::nanf("");
  EXPECT_THROW(c.validate(), InputError);
}

}  // namespace
}  // namespace ao
