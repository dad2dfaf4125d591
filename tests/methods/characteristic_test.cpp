// Characteristic functions (VAO fig. 2) on configurations whose inner/outer split and view-axis
// distance are known exactly.
#include "ao/methods/characteristic.h"

#include <gtest/gtest.h>

#include "screen_space_fixtures.h"

namespace ao {
namespace {

TEST(Characteristic, DepthBufferDistanceIsDepthDifferenceAtTheProjection) {
  const auto s = test::builtin_gbuffer("plane");
  const DepthBufferCharacteristic ch(s.g);
  const int x = test::kWidth / 2, y = test::kHeight / 2;
  ASSERT_TRUE(s.g.covered(x, y));
  const Vec3 p = s.g.position(x, y);
  // Along the view ray through the pixel: 0.1 nearer is outer by 0.1 of depth, 0.1 farther is inner.
  const Vec3 nearer = p * (1.0f - 0.1f / -p.z), farther = p * (1.0f + 0.1f / -p.z);
  EXPECT_NEAR(ch.distance(nearer.x, nearer.y, nearer.z), 0.1f, 1e-4f);
  EXPECT_NEAR(ch.distance(farther.x, farther.y, farther.z), -0.1f, 1e-4f);
}

TEST(Characteristic, DepthBufferOffScreenAndBehindCameraAreFree) {
  const auto s = test::builtin_gbuffer("plane");
  const DepthBufferCharacteristic ch(s.g);
  EXPECT_EQ(ch.distance(1e4f, 0, -1), kInfinity);  // far outside the frustum
  EXPECT_EQ(ch.distance(0, 0, 1), kInfinity);      // behind the camera
}

TEST(Characteristic, ImplicitPlaneTaylorDistanceIsExact) {
  // Plane through (0,0,-5) facing (0, 0.6, 0.8): along -z the surface is f / (df/dz) away.
  ImplicitCharacteristic ch;
  ch.add(ImplicitPrimitive::half_space({0, 0.6f, 0.8f}, {0, 0, -5}));
  const Vec3 p{0.3f, 0.2f, -4.0f};
  const float f = dot(Vec3{0, 0.6f, 0.8f}, p - Vec3{0, 0, -5});
  EXPECT_NEAR(ch.distance(p.x, p.y, p.z), f / 0.8f, 1e-5f);
  // Moving p deeper by that amount lands on the plane.
  const float d = ch.distance(p.x, p.y, p.z);
  EXPECT_NEAR(ch.distance(p.x, p.y, p.z - d), 0.0f, 1e-5f);
}

TEST(Characteristic, ImplicitSphereAndWedgeClassifyInsideAndOutside) {
  ImplicitCharacteristic sphere;
  sphere.add(ImplicitPrimitive::sphere_exterior({0, 0, -5}, 1));
  EXPECT_GT(sphere.distance(0, 0, -3.5f), 0.0f);  // in front of the sphere
  EXPECT_LT(sphere.distance(0, 0, -4.5f), 0.0f);  // inside it
  // On the axis the sphere's SDF is linear in z: the Taylor step is exact.
  EXPECT_NEAR(sphere.distance(0, 0, -3.5f), 0.5f, 1e-5f);
  // A wedge: floor y >= 0 and wall z >= -5; the wall faces the camera.
  ImplicitCharacteristic wedge;
  wedge.add(ImplicitPrimitive::half_space({0, 1, 0}, {0, 0, 0})).add(ImplicitPrimitive::half_space({0, 0, 1}, {0, 0, -5}));
  EXPECT_NEAR(wedge.distance(0, 1, -4), 1.0f, 1e-5f);   // the wall is 1 behind; the floor is parallel to the view axis
  EXPECT_LT(wedge.distance(0, -1, -4), -1e30f);  // under the floor: inner along the whole line
}

TEST(Characteristic, HeightFieldOfZeroMapIsItsPlaneAndBumpsOcclude) {
  const Image<float> flat(8, 8, 0.0f);
  HeightFieldCharacteristic hf;
  hf.origin = {0, 0, -5};
  hf.frame = Frame::from_normal({0, 0, 1});  // plane facing the camera
  hf.map = flat.view();
  hf.period = 1;
  hf.amplitude = 0.2f;
  EXPECT_NEAR(hf.distance(0.1f, 0.1f, -4.9f), 0.1f, 1e-5f);
  const Image<float> bumps = make_bump_map(64, 1);  // one dome, top at the map's centre
  hf.map = bumps.view();
  const Vec3 top = hf.origin + hf.frame.to_world({0.5f, 0.5f, 0.0f});
  EXPECT_LT(hf.distance(top.x, top.y, top.z + 0.1f), 0.0f) << "0.1 above the plane is inside a dome 0.2 high";
  EXPECT_GT(hf.distance(top.x, top.y, top.z + 0.3f), 0.0f);
  EXPECT_NEAR(hf.distance(top.x, top.y, top.z + 0.3f), 0.1f, 0.01f) << "the dome's top is flat to first order";
}

TEST(Characteristic, ProductTakesTheNearerSurface) {
  ImplicitCharacteristic a, b;
  a.add(ImplicitPrimitive::half_space({0, 0, 1}, {0, 0, -5}));
  b.add(ImplicitPrimitive::half_space({0, 0, 1}, {0, 0, -6}));
  const ProductCharacteristic<ImplicitCharacteristic, ImplicitCharacteristic> ab{a, b};
  EXPECT_NEAR(ab.distance(0, 0, -4), 1.0f, 1e-5f);
  EXPECT_LT(ab.distance(0, 0, -5.5f), 0.0f);
}

}  // namespace
}  // namespace ao
