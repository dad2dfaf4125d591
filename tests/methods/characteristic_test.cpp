// SPDX-License-Identifier: Apache-2.0
// Characteristic functions (VAO fig. 2) on configurations whose inner/outer split and view-axis
// distance are known exactly.
#include "ao/methods/characteristic.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "ao/core/error.h"

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

TEST(Characteristic, DepthBufferOffScreenReadsTheEdgeAndBehindCameraIsFree) {
  const auto s = test::builtin_gbuffer("plane");
  const DepthBufferCharacteristic ch(s.g);
  EXPECT_NE(ch.distance(1e4f, 0, -1), kInfinity);  // far outside the frustum: the nearest edge pixel (clamp to edge)
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

TEST(Characteristic, SilhouetteEliminatedFreesOnlyPointsFarBehindTheSurface) {
  ImplicitCharacteristic wall;  // faces the camera at z = -5
  wall.add(ImplicitPrimitive::half_space({0, 0, 1}, {0, 0, -5}));
  const SilhouetteEliminated<ImplicitCharacteristic> near{wall, 1.0f};
  EXPECT_NEAR(near.distance(0, 0, -4), 1.0f, 1e-5f);    // in front: unchanged
  EXPECT_NEAR(near.distance(0, 0, -5.5f), -0.5f, 1e-5f);  // less than the limit behind: still inner
  EXPECT_EQ(near.distance(0, 0, -6.5f), kInfinity);      // more than the limit behind: a distant foreground object
  const SilhouetteEliminated<ImplicitCharacteristic> off{wall};
  EXPECT_NEAR(off.distance(0, 0, -6.5f), -1.5f, 1e-5f);
}

// A camera looking at the scene from an oblique direction, so that no axis is shared by the spaces.
Camera oblique_camera() {
  Camera c;
  c.eye = {3.0f, 2.5f, 4.0f};
  c.target = {-0.5f, 0.3f, 0.2f};
  c.up = {0.1f, 1.0f, 0.0f};
  return c;
}

// The camera transform is rigid: the camera-space function classifies the camera image of every
// world point as the world-space description does, and keeps its signed value.
TEST(Characteristic, ImplicitSurfaceFromTheSceneKeepsItsValuesInCameraSpace) {
  const Camera c = oblique_camera();
  ImplicitSurface world;
  world.primitives = {ImplicitSurfacePrimitive::half_space({0, 0, 0}, {0, 1, 0}), ImplicitSurfacePrimitive::sphere_exterior({0.5f, 1, -0.5f}, 1)};
  const ImplicitCharacteristic ch = implicit_characteristic(world, c);
  ASSERT_EQ(ch.count, 2);
  for (int i = 0; i < 200; ++i) {
    const Vec3 p{std::sin(1.7f * i) * 2, std::cos(0.9f * i) * 1.5f, std::sin(0.37f * i + 1) * 2};
    const Vec3 q = c.world_to_camera_point(p);
    float f = kInfinity;
    for (int k = 0; k < ch.count; ++k) f = std::min(f, ch.primitives[static_cast<std::size_t>(k)].value(q));
    ASSERT_NEAR(f, world.value(p), 1e-4f) << "point " << i;
    ASSERT_EQ(ch.distance(q.x, q.y, q.z) >= 0, world.value(p) >= 0) << "point " << i;
  }
}

TEST(Characteristic, HeightFieldFromTheSceneKeepsItsLocalCoordinatesInCameraSpace) {
  const Camera c = oblique_camera();
  HeightFieldSurface world;
  world.origin = {-1, 0.1f, 2};
  world.frame = {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}};
  world.map = std::make_shared<const Image<float>>(make_bump_map(32, 2));
  world.period = 1.5f;
  world.amplitude = 0.3f;
  const HeightFieldCharacteristic ch = height_field_characteristic(world, c);
  EXPECT_EQ(ch.map.data, world.map->data()) << "the map is shared, not copied";
  for (int i = 0; i < 200; ++i) {
    const Vec3 p{std::sin(1.3f * i) * 2, 0.1f + 0.35f * std::cos(0.7f * i), std::sin(0.51f * i + 2) * 2};
    const Vec3 l = world.frame.to_local(p - world.origin);
    const Vec3 lc = ch.frame.to_local(c.world_to_camera_point(p) - ch.origin);
    ASSERT_NEAR(lc.x, l.x, 1e-4f) << "point " << i;
    ASSERT_NEAR(lc.y, l.y, 1e-4f) << "point " << i;
    ASSERT_NEAR(lc.z, l.z, 1e-4f) << "point " << i;
  }
}

TEST(Characteristic, BadAnalyticDescriptionsAreInputErrors) {
  const Camera c = oblique_camera();
  EXPECT_THROW(implicit_characteristic(ImplicitSurface{}, c), InputError);
  ImplicitSurface five;
  five.primitives.assign(5, ImplicitSurfacePrimitive::half_space({0, 0, 0}, {0, 1, 0}));
  EXPECT_THROW(implicit_characteristic(five, c), InputError);
  HeightFieldSurface hf;
  EXPECT_THROW(height_field_characteristic(hf, c), InputError) << "no map";
  hf.map = std::make_shared<const Image<float>>(make_bump_map(8, 1));
  EXPECT_NO_THROW(height_field_characteristic(hf, c));
  for (float period : {0.0f, -1.0f, kInfinity}) {
    HeightFieldSurface bad = hf;
    bad.period = period;
    EXPECT_THROW(height_field_characteristic(bad, c), InputError) << period;
  }
  HeightFieldSurface skew = hf;
  skew.frame.b = normalize(Vec3{0.3f, 0, 1});
  EXPECT_THROW(height_field_characteristic(skew, c), InputError);
  HeightFieldSurface scaled = hf;
  scaled.frame.n = {0, 2, 0};
  EXPECT_THROW(height_field_characteristic(scaled, c), InputError);
}

// The built-in displaced floor is the mesh of its own height field: every vertex lies on the
// surface the characteristic function reads (texel centres, where the bilinear lookup is exact), and
// the flat triangles depart from the bilinear patches by little (measured: at most 0.0009 at
// triangle centroids, a tenth of a pixel's footprint at the preferred view's distance at 720 lines,
// so well inside the depth-test bias).
TEST(Characteristic, DisplacedSceneFloorMeshLiesOnItsHeightField) {
  const Scene s = make_builtin_scene("displaced");
  ASSERT_TRUE(s.analytic.height_field.has_value());
  const Camera c = *s.preferred_view;
  const HeightFieldCharacteristic ch = height_field_characteristic(*s.analytic.height_field, c);
  const Mesh& floor = s.meshes.at(0);
  ASSERT_EQ(floor.name, "floor");
  float worst_vertex = 0, worst_centroid = 0;
  for (const Vec3& p : floor.positions) worst_vertex = std::max(worst_vertex, std::abs(ch.value(c.world_to_camera_point(p), nullptr)));
  for (std::size_t t = 0; t < floor.indices.size(); t += 3) {
    const Vec3 centroid = (floor.positions[floor.indices[t]] + floor.positions[floor.indices[t + 1]] + floor.positions[floor.indices[t + 2]]) / 3.0f;
    worst_centroid = std::max(worst_centroid, std::abs(ch.value(c.world_to_camera_point(centroid), nullptr)));
  }
  std::printf("displaced floor: |f| at vertices <= %.2g, at triangle centroids <= %.2g\n", worst_vertex, worst_centroid);
  EXPECT_LT(worst_vertex, 2e-5f);  // float rounding of camera-space coordinates ~10 units from the eye
  EXPECT_LT(worst_centroid, 0.002f);
  const Bounds3 b = floor.bounds();
  EXPECT_NEAR(b.lo.x, -4.0f, 1e-5f);
  EXPECT_NEAR(b.hi.x, 4.0f, 1e-5f);
  EXPECT_NEAR(b.lo.z, -4.0f, 1e-5f);
  EXPECT_NEAR(b.hi.z, 4.0f, 1e-5f);
}

}  // namespace
}  // namespace ao
