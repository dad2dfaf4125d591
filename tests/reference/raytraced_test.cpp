// SPDX-License-Identifier: Apache-2.0
// The ray-traced ground truth against configurations with known answers. Tolerances come from
// the estimator's own reported standard error: a correct estimator lands within 4 standard
// errors of the truth except with probability ~6e-5 (and scrambled Sobol errors are smaller
// than the reported, variance-based standard error).
#include "ao/reference/raytraced.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <atomic>
#include <cmath>

#include "ao/gbuffer/render_gbuffer.h"
#include "ao/scene/procedural.h"


namespace ao {
namespace {

constexpr float kSigmas = 4.0f;

Scene prepared(Scene s) {
  validate_and_prepare(s);
  return s;
}

// Floor y = 0 (z in [0, L]) and an infinite-looking wall z = 0 facing +z.
Scene floor_and_wall() {
  Scene s;
  s.name = "floor-and-wall";
  const float L = 1000.0f;
  s.meshes.push_back(make_quad({-L, 0, L}, {L, 0, L}, {L, 0, 0}, {-L, 0, 0}));
  s.meshes.push_back(make_quad({-L, 0, 0}, {L, 0, 0}, {L, L, 0}, {-L, L, 0}));
  return prepared(std::move(s));
}

TEST(Raytraced, OpenPlaneIsFullyVisibleForEveryMembership) {
  const Scene s = make_builtin_scene("plane");
  const RayScene rs(s);
  for (Membership m : {Membership::Step, Membership::Linear, Membership::Sqrt, Membership::Cubic, Membership::Exp}) {
    const Falloff f{m, 2.0f};
    const auto e = estimate_visibility(rs, {0.3f, 0, -1.2f}, {0, 1, 0}, f, {.samples = 256}, 7);
    EXPECT_EQ(e.visibility, 1.0f) << to_string(m);
    EXPECT_EQ(e.std_error, 0.0f) << to_string(m);
  }
}

// On the crease, about the floor's normal, the wall removes the half of the hemisphere behind
// it, and by symmetry half of the cosine-weighted measure: V = 1/2. (The point sits 1e-4 in front
// of the wall so that no ray starts inside the wall's plane.)
TEST(Raytraced, WedgeCreaseIsHalfVisibleAboutFaceNormal) {
  const Scene s = make_builtin_scene("wedge");
  const RayScene rs(s);
  const auto e = estimate_visibility(rs, {0, 0, 1e-4f}, {0, 1, 0}, {Membership::Step, 1e4f}, {.samples = 4096}, 3);
  EXPECT_NEAR(e.visibility, 0.5f, kSigmas * e.std_error + 1e-3f);
  EXPECT_GT(e.std_error, 0.0f);
}

// About the bisector n = (0,1,1)/sqrt(2), project cosine-weighted directions onto the tangent disk
// with axes x and (0,1,-1)/sqrt(2): a direction (a, b) is blocked by the floor when
// a^2 + 2 b^2 > 1 with b < 0, and by the wall in the mirror image. The open part is the ellipse
// with semi-axes 1 and 1/sqrt(2), area pi/sqrt(2), so V = 1/sqrt(2), not 1/2.
TEST(Raytraced, WedgeCreaseAboutBisectorIsOneOverSqrtTwo) {
  const Scene s = make_builtin_scene("wedge");
  const RayScene rs(s);
  const auto e = estimate_visibility(rs, {0, 0, 0}, normalize(Vec3{0, 1, 1}), {Membership::Step, 1e4f}, {.samples = 4096}, 3);
  EXPECT_NEAR(e.visibility, 1.0f / std::sqrt(2.0f), kSigmas * e.std_error + 1e-3f);
}

// With a = d/R <= 1 the wall blocks the cosine-weighted directions whose projection onto the
// floor's unit disk lies beyond the chord at distance a: the disk segment of area
// acos(a) - a*sqrt(1 - a^2), out of pi.
TEST(Raytraced, FloorNearWallMatchesDiskSegmentFormula) {
  const Scene s = floor_and_wall();
  const RayScene rs(s);
  const float R = 1.0f;
  for (float a : {0.1f, 0.3f, 0.5f, 0.8f, 1.0f}) {
    const auto e = estimate_visibility(rs, {0, 0, a * R}, {0, 1, 0}, {Membership::Step, R}, {.samples = 4096}, 11);
    const float expected = 1.0f - (std::acos(a) - a * std::sqrt(1.0f - a * a)) / kPi;
    EXPECT_NEAR(e.visibility, expected, kSigmas * e.std_error + 2e-3f) << "a = " << a;
  }
}

// The same configuration for the other memberships: the open fraction is the integral over the
// unit disk (uniform, area pi) of mu(distance along the ray to the wall). A direction whose
// projection is at (r cos phi, r sin phi) with the wall at distance a in the -z direction... we
// integrate numerically on a fine polar grid: the projection point (u, v) on the disk gives the
// direction w = (u, sqrt(1 - u^2 - v^2), v) in (x, y, z); it hits the wall z = -d... (wall at z = 0,
// point at z = d) when v < 0, at distance D = d / (-v).
float wall_quadrature(const Falloff& f, float d) {
  const int n = 2000;
  double sum = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u = -1.0 + (i + 0.5) * 2.0 / n, v = -1.0 + (j + 0.5) * 2.0 / n;
      if (u * u + v * v > 1.0) continue;
      const float D = v < 0 ? static_cast<float>(d / -v) : kInfinity;
      sum += f.mu(D);
    }
  return static_cast<float>(sum * (4.0 / (double(n) * n)) / M_PI);
}

TEST(Raytraced, FloorNearWallMatchesQuadratureForEveryMembership) {
  const Scene s = floor_and_wall();
  const RayScene rs(s);
  const float d = 0.4f;
  for (Membership m : {Membership::Step, Membership::Linear, Membership::Sqrt, Membership::Cubic, Membership::Exp}) {
    const Falloff f{m, 1.0f};
    const auto e = estimate_visibility(rs, {0, 0, d}, {0, 1, 0}, f, {.samples = 4096}, 5);
    // 2e-3: the quadrature's own error on a 2000 x 2000 grid with a discontinuous integrand.
    EXPECT_NEAR(e.visibility, wall_quadrature(f, d), kSigmas * e.std_error + 2e-3f) << to_string(m);
  }
}

TEST(Raytraced, InsideClosedRoomIsFullyOccludedWithLargeRadius) {
  const Scene s = make_builtin_scene("box-room");
  const RayScene rs(s);
  const Camera cam = [&] {
    Camera c = *s.preferred_view;
    c.width = 64;
    c.height = 48;
    return c;
  }();
  const GBuffer g = render_gbuffer(rs, cam);
  const auto img = render_raytraced(rs, g, {Membership::Step, 100.0f}, {.samples = 64}, 1);
  for (std::size_t i = 0; i < img.visibility.size(); ++i) {
    ASSERT_TRUE(g.covered(i)) << "the room encloses the camera, every pixel sees a wall";
    EXPECT_EQ(img.visibility[i], 0.0f) << "pixel " << i;
  }
}

TEST(Raytraced, StandardErrorFallsAsOneOverSqrtSamples) {
  const Scene s = floor_and_wall();
  const RayScene rs(s);
  const Falloff f{Membership::Step, 1.0f};
  const auto e256 = estimate_visibility(rs, {0, 0, 0.5f}, {0, 1, 0}, f, {.samples = 256}, 9);
  const auto e4096 = estimate_visibility(rs, {0, 0, 0.5f}, {0, 1, 0}, f, {.samples = 4096}, 9);
  // sqrt(4096 / 256) = 4; the sample variance itself fluctuates by a few percent.
  EXPECT_NEAR(e256.std_error / e4096.std_error, 4.0f, 0.4f);
}

TEST(Raytraced, TargetErrorStopsEachPixelBelowIt) {
  const Scene s = make_builtin_scene("sphere-on-plane");
  const RayScene rs(s);
  Camera cam = *s.preferred_view;
  cam.width = 40;
  cam.height = 30;
  const GBuffer g = render_gbuffer(rs, cam);
  RaytracedParams p{.samples = 16384, .target_error = 0.01f, .min_samples = 64};
  const auto img = render_raytraced(rs, g, {Membership::Step, 1.0f}, p, 2);
  EXPECT_LE(img.max_std_error, 0.01);
  EXPECT_LT(img.rays, static_cast<std::uint64_t>(16384) * 40 * 30 / 4) << "open pixels should stop early";
}

// Progress counts covered pixels (the pixels that cast rays), not tiles of the image, so a bar's
// rate is not skewed by background: it ends at the covered count, which is less than the image.
TEST(Raytraced, ProgressCountsCoveredPixels) {
  const Scene s = make_builtin_scene("sphere-on-plane");
  const RayScene rs(s);
  Camera cam = *s.preferred_view;
  cam.width = 64;
  cam.height = 48;
  cam.eye = cam.eye + (cam.eye - cam.target) * 2.0f;  // further back: the floor's far edge and sky in view
  const GBuffer g = render_gbuffer(rs, cam);
  std::size_t covered = 0;
  for (std::size_t i = 0; i < g.object_id.size(); ++i) covered += g.covered(i) ? 1 : 0;
  ASSERT_GT(covered, 0u);
  ASSERT_LT(covered, g.object_id.size()) << "the view must show some background";
  std::atomic<std::size_t> last_done{0}, last_total{0}, calls{0};
  const ProgressFn progress = [&](std::size_t done, std::size_t total) {
    std::size_t seen = last_done.load();
    while (done > seen && !last_done.compare_exchange_weak(seen, done)) {
    }
    last_total = total;
    ++calls;
  };
  render_raytraced(rs, g, {Membership::Step, 1.0f}, {.samples = 16}, 1, progress);
  EXPECT_GT(calls.load(), 1u);
  EXPECT_EQ(last_total.load(), covered);
  EXPECT_EQ(last_done.load(), covered);
  last_done = 0, last_total = 0;
  render_gbuffer(rs, cam, progress);  // every pixel casts a primary ray
  EXPECT_EQ(last_total.load(), g.object_id.size());
  EXPECT_EQ(last_done.load(), g.object_id.size());
}

TEST(Raytraced, VisibilityIsMonotoneInRadius) {
  const Scene s = make_builtin_scene("sphere-on-plane");
  const RayScene rs(s);
  float previous = 1.0f;
  for (float R : {0.1f, 0.3f, 1.0f, 3.0f}) {
    // Same seed, same directions: a larger R can only turn open directions into occluded ones.
    const auto e = estimate_visibility(rs, {1.2f, 0, 0}, {0, 1, 0}, {Membership::Step, R}, {.samples = 1024}, 4);
    EXPECT_LE(e.visibility, previous) << "R = " << R;
    previous = e.visibility;
  }
  EXPECT_LT(previous, 1.0f);
}

TEST(Raytraced, RejectsBadParameters) {
  EXPECT_THROW((RaytracedParams{.samples = 0}.validate()), InputError);
  EXPECT_THROW((RaytracedParams{.samples = 1 << 24}.validate()), InputError);
  EXPECT_THROW((RaytracedParams{.target_error = -1.0f}.validate()), InputError);
  EXPECT_THROW((Falloff{Membership::Step, 0.0f}.validate()), InputError);
  EXPECT_THROW((Falloff{Membership::Step, std::nanf("")}.validate()), InputError);
  RaytracedParams p;
  EXPECT_THROW(from_json(nlohmann::json{{"sample", 3}}, p), InputError);
}

}  // namespace
}  // namespace ao
