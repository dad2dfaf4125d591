// SPDX-License-Identifier: Apache-2.0
// The sun's direct-light pass against answers known in closed form: Ld = a/pi E max(0, n.l) in the
// open, 0 in a shadow and on faces turned away.
#include "ao/reference/direct_light.h"

#include <gtest/gtest.h>

#include <cmath>

#include "ao/core/error.h"
#include "methods/screen_space_fixtures.h"
#include "support/scenes.h"

namespace ao {
namespace {

// Looking down at a floor y = 0 (mesh 1) from above and in front.
Camera view_from_above() {
  Camera c;
  c.eye = {0, 6, 4};
  c.target = {0, 0, 0};
  return c;
}

// Relative float rounding of the normal's round trip camera -> world and of the products.
void expect_radiance(Vec3 got, Vec3 want, std::size_t pixel) {
  EXPECT_NEAR(got.x, want.x, 1e-6f * (1 + want.x)) << "pixel " << pixel;
  EXPECT_NEAR(got.y, want.y, 1e-6f * (1 + want.y)) << "pixel " << pixel;
  EXPECT_NEAR(got.z, want.z, 1e-6f * (1 + want.z)) << "pixel " << pixel;
}

TEST(DirectLight, OpenPlaneFacingTheSunHasAlbedoTimesEOverPiTimesCosine) {
  const Vec3 albedo{0.25f, 0.5f, 0.75f};
  auto s = test::scene_gbuffer(test::scene_of({make_quad({-50, 0, 50}, {50, 0, 50}, {50, 0, -50}, {-50, 0, -50}, albedo)}), view_from_above());
  struct Case {
    Sun sun;
    float cos_theta;
  };
  // Straight above with E = pi: Ld = a (a white surface would be as bright as the sky); then a
  // slanted sun (n.l = 0.6) of another strength.
  for (const Case& c : {Case{{{0, 1, 0}, kPi}, 1.0f}, Case{{{0, 0.6f, 0.8f}, 2.0f}, 0.6f}}) {
    const Image<Vec3> ld = render_direct_light(*s.rays, s.g, c.sun);
    int covered = 0;
    for (std::size_t i = 0; i < ld.size(); ++i) {
      if (!s.g.covered(i)) {
        ASSERT_EQ(ld[i], (Vec3{0, 0, 0}));
        continue;
      }
      ++covered;
      expect_radiance(ld[i], albedo * (c.sun.irradiance * c.cos_theta / kPi), i);
    }
    EXPECT_GT(covered, test::kWidth * test::kHeight / 2);
  }
  // From below the floor: its seen side faces away, so no light and no ray.
  const Image<Vec3> below = render_direct_light(*s.rays, s.g, Sun{{0, -1, 0}, kPi});
  for (const Vec3& v : below.pixels()) ASSERT_EQ(v, (Vec3{0, 0, 0}));
}

// A unit box on the floor and a sun at 45 degrees from +x: the box's shadow covers the floor from
// x = -0.5 to x = -1.5 over the box's depth z in [-0.5, 0.5]; beyond it the floor is open.
TEST(DirectLight, ShadowOfABoxIsDarkAndTheRestOfTheFloorIsLit) {
  const Vec3 albedo{0.8f, 0.8f, 0.8f};
  auto s = test::scene_gbuffer(test::scene_of({make_quad({-50, 0, 50}, {50, 0, 50}, {50, 0, -50}, {-50, 0, -50}, albedo),
                                               make_box({-0.5f, 0, -0.5f}, {0.5f, 1, 0.5f}, albedo)}),
                               view_from_above());
  const Sun sun{normalize(Vec3{1, 1, 0}), kPi};
  const Image<Vec3> ld = render_direct_light(*s.rays, s.g, sun);
  const Vec3 open = albedo * (sun.irradiance * std::sqrt(0.5f) / kPi);
  int shadowed = 0, lit = 0;
  for (std::size_t i = 0; i < ld.size(); ++i) {
    if (s.g.object_id[i] != 1) continue;  // floor only
    const Vec3 p = s.g.camera.camera_to_world_point(s.g.position[i]);
    // 0.1 world units of margin around the shadow's edges (pixel footprints are ~0.05 here).
    if (p.x > -1.4f && p.x < -0.6f && std::abs(p.z) < 0.4f) {
      ASSERT_EQ(ld[i], (Vec3{0, 0, 0})) << "pixel " << i << " at x = " << p.x << ", z = " << p.z << " is in the box's shadow";
      ++shadowed;
    } else if (p.x > -0.4f || p.x < -1.6f || std::abs(p.z) > 0.6f) {
      expect_radiance(ld[i], open, i);
      ++lit;
    }
  }
  EXPECT_GT(shadowed, 50);
  EXPECT_GT(lit, 1000);
}

TEST(DirectLight, RejectsBadSuns) {
  EXPECT_THROW((Sun{{0, 0, 0}, kPi}.validate()), InputError);
  EXPECT_THROW((Sun{{0, 2, 0}, kPi}.validate()), InputError);  // not normalised
  EXPECT_THROW((Sun{{0, std::nanf(""), 0}, kPi}.validate()), InputError);
  EXPECT_THROW((Sun{{0, 1, 0}, -1.0f}.validate()), InputError);
  EXPECT_THROW((Sun{{0, 1, 0}, kInfinity}.validate()), InputError);
  EXPECT_NO_THROW((Sun{{0, 1, 0}, 0.0f}.validate()));
}

}  // namespace
}  // namespace ao
