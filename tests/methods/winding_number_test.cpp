// SPDX-License-Identifier: Apache-2.0
// Generalized winding numbers: known answers (a closed mesh, a flat sheet, a sphere with a cap cut
// off, seen from its centre), the jump across a surface, and the fast hierarchy against the exact
// sum.
#include "ao/methods/cone/winding_number.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "ao/core/affine.h"
#include "ao/core/error.h"
#include "ao/scene/procedural.h"

#include "support/open_sheets.h"

namespace ao {
namespace {

TEST(WindingNumber, ClosedMeshIsOneInsideAndZeroOutside) {
  const Mesh sphere = make_sphere({0.2f, -0.1f, 0.3f}, 1.0f, 48, 24);
  const WindingNumber w(sphere.positions, sphere.indices);
  for (Vec3 q : {Vec3{0.2f, -0.1f, 0.3f}, Vec3{0.7f, 0.2f, 0.1f}, Vec3{-0.4f, -0.5f, 0.6f}}) {
    // The exact sum of a closed mesh is an integer up to rounding (double sums of ~2,000 atan2).
    EXPECT_NEAR(w.exact(q), 1.0, 1e-9);
    // 0.01: the hierarchy's truncation error (FastAgreesWithTheExactSum).
    EXPECT_NEAR(w(q), 1.0, 0.01);
  }
  for (Vec3 q : {Vec3{3, 0, 0}, Vec3{0.2f, 1.5f, 0.3f}, Vec3{-5, -5, 5}}) {
    EXPECT_NEAR(w.exact(q), 0.0, 1e-9);
    EXPECT_NEAR(w(q), 0.0, 0.01);
  }
  // Turning every triangle over negates w.
  const Mesh flipped = test::turned_over(sphere);
  EXPECT_NEAR(WindingNumber(flipped.positions, flipped.indices).exact({0.2f, -0.1f, 0.3f}), -1.0, 1e-9);
}

TEST(WindingNumber, FlatSheetIsMinusHalfInFrontAndPlusHalfBehind) {
  const Mesh quad = make_quad({-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1});  // facing +y
  const WindingNumber w(quad.positions, quad.indices);
  // At height h over the centre of a square of half-side 1 the solid angle is
  // 4 asin(1 / (1 + h^2)) (two halves of the exact rectangle formula), so w = -asin(1/(1+h^2)) / pi.
  for (float h : {1e-4f, 0.3f, 2.0f}) {
    const double expected = std::asin(1.0 / (1.0 + double(h) * h)) / 3.14159265358979323846;
    EXPECT_NEAR(w.exact({0, h, 0}), -expected, 1e-6) << h;
    EXPECT_NEAR(w.exact({0, -h, 0}), expected, 1e-6) << h;
  }
  // On the sheet itself: the mean of its two sides.
  EXPECT_EQ(w.exact({0.1f, 0, 0.2f}), 0.0);
}

// A unit sphere without the cap above the cone of half-angle a about +y: from the centre the hole
// subtends 2 pi (1 - cos a), so w = 1 - (1 - cos a) / 2.
TEST(WindingNumber, SphereWithACapCutOffSeenFromItsCentre) {
  const Mesh sphere = make_sphere({0, 0, 0}, 1.0f, 192, 96);
  for (double a : {0.3, 1.0, 2.0}) {
    const Mesh open = test::cut(sphere, [a](Vec3 c) { return c.y / length(c) < std::cos(a); });
    const WindingNumber w(open.positions, open.indices);
    const double expected = 1.0 - (1.0 - std::cos(a)) / 2.0;
    // 0.01: the cut follows whole triangles (96 rings: the rim lies up to 1/96 of pi off the cone).
    EXPECT_NEAR(w.exact({0, 0, 0}), expected, 0.01) << "a = " << a;
    EXPECT_NEAR(w({0, 0, 0}), w.exact({0, 0, 0}), 0.01) << "a = " << a;
  }
}

// Crossing a surface from front to back adds one, also on open meshes.
TEST(WindingNumber, JumpsByOneAcrossTheSurface) {
  const Mesh bowl = test::make_bowl();
  const WindingNumber w(bowl.positions, bowl.indices);
  for (std::size_t t = 0; t < bowl.triangle_count(); t += 97) {
    const Vec3 a = bowl.positions[bowl.indices[3 * t]], b = bowl.positions[bowl.indices[3 * t + 1]], c = bowl.positions[bowl.indices[3 * t + 2]];
    const Vec3 n = normalize(cross(b - a, c - a)), centre = (a + b + c) * (1.0f / 3.0f);
    // 1e-5 off a triangle of the 96 x 48 bowl (sides ~0.06): its neighbours shift w by O(1e-5 / 0.06).
    EXPECT_NEAR(w.exact(centre - n * 1e-5f) - w.exact(centre + n * 1e-5f), 1.0, 1e-3) << "triangle " << t;
  }
}

// The hierarchy (beta = 2, terms to the Hessian) against the exact sum at points all over and
// around open meshes and a torus. Bound 0.02: measured 0.0029 (arch), 0.0026 (bowl), 0.0050
// (torus) at worst, and 0.0035 over 200 points around the 20,000-triangle ChineseDragon-10kv.
TEST(WindingNumber, FastAgreesWithTheExactSum) {
  for (const Mesh& m : {test::make_holed_arch(), test::make_bowl(), make_torus({0, 0, 0}, 1.0f, 0.35f, 64, 24)}) {
    const WindingNumber w(m.positions, m.indices);
    Bounds3 b = m.bounds();
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-0.25f, 1.25f);
    double worst = 0;
    for (int i = 0; i < 200; ++i) {
      const Vec3 q = b.lo + b.extent() * Vec3{u(rng), u(rng), u(rng)};
      worst = std::max(worst, std::abs(w(q) - w.exact(q)));
    }
    EXPECT_LT(worst, 0.02) << m.triangle_count() << " triangles";
  }
}

// The nearest triangle's distance, signed by its side: negative in front, positive behind.
TEST(WindingNumber, SignedDistanceToTheNearestTriangle) {
  Mesh two = make_quad({-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1});  // facing +y at y = 0
  append_mesh(two, make_quad({-1, 2, -1}, {1, 2, -1}, {1, 2, 1}, {-1, 2, 1}));  // facing -y at y = 2
  const WindingNumber w(two.positions, two.indices);
  EXPECT_NEAR(w.signed_distance({0.2f, 0.3f, 0.1f}), -0.3, 1e-6) << "in front of the lower one";
  EXPECT_NEAR(w.signed_distance({0.2f, 1.5f, 0.1f}), -0.5, 1e-6) << "in front of the upper one";
  EXPECT_NEAR(w.signed_distance({0.2f, -0.4f, 0.1f}), 0.4, 1e-6) << "behind the lower one";
  EXPECT_NEAR(w.signed_distance({3.0f, -0.5f, 0.0f}), std::sqrt(4.0 + 0.25), 1e-6) << "past its edge, below";
  EXPECT_EQ(WindingNumber().signed_distance({0, 0, 0}), std::numeric_limits<double>::infinity());
  // The branch and bound against every triangle on its own, around the half sphere shell.
  const Mesh bowl = test::make_bowl(1.0f, 48, 24);
  const WindingNumber all(bowl.positions, bowl.indices);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.5f, 1.5f);
  for (int k = 0; k < 100; ++k) {
    const Vec3 q{u(rng), u(rng) + 1.0f, u(rng)};
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t t = 0; t < bowl.triangle_count(); ++t) {
      const double d = WindingNumber(bowl.positions, std::span(bowl.indices).subspan(3 * t, 3)).signed_distance(q);
      if (std::abs(d) < std::abs(nearest)) nearest = d;
    }
    EXPECT_NEAR(all.signed_distance(q), nearest, 1e-6) << q.x << ", " << q.y << ", " << q.z;
  }
}

// Rays against the hierarchy: a unit quad facing +y met from above (its front) and from below (its
// back) at the distance to its plane, missed beside it and beyond t_max; on a sphere from its centre
// every ray meets the inside (the backs) at the radius, within the tessellation's sag.
TEST(WindingNumber, FirstHitIsTheNearestTriangleAndItsSide) {
  const Mesh quad = make_quad({-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1});  // facing +y
  const WindingNumber w(quad.positions, quad.indices);
  const float inf = std::numeric_limits<float>::infinity();
  WindingNumber::Hit h = w.first_hit({0.2f, 2, 0.3f}, {0, -1, 0}, 0, inf);
  EXPECT_FLOAT_EQ(h.t, 2.0f);
  EXPECT_EQ(h.side, -1);
  h = w.first_hit({0.2f, -0.5f, 0.3f}, {0, 2, 0}, 0, inf);  // t in lengths of d
  EXPECT_FLOAT_EQ(h.t, 0.25f);
  EXPECT_EQ(h.side, 1);
  EXPECT_EQ(w.first_hit({1.5f, 2, 0}, {0, -1, 0}, 0, inf).side, 0);  // beside it
  EXPECT_EQ(w.first_hit({0, 2, 0}, {0, -1, 0}, 0, 1.5f).side, 0);    // beyond t_max
  EXPECT_EQ(w.first_hit({0, 2, 0}, {0, 1, 0}, 0, inf).side, 0);      // away from it
  EXPECT_EQ(w.first_hit({0, 2, 0}, {1, 0, 0}, 0, inf).side, 0);      // parallel to it
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(w.first_hit({0.2f, 2, 0.3f}, {nan, nan, nan}, 0, inf).side, 0);  // a degenerate face's normal

  const Mesh sphere = make_sphere({0, 0, 0}, 1.0f, 96, 48);
  const WindingNumber ws(sphere.positions, sphere.indices);
  std::mt19937 rng(3);
  std::normal_distribution<float> g;
  for (int k = 0; k < 200; ++k) {
    const Vec3 d = normalize(Vec3{g(rng), g(rng), g(rng)});
    const WindingNumber::Hit in = ws.first_hit({0, 0, 0}, d, 0, inf);
    EXPECT_EQ(in.side, 1) << k;
    EXPECT_NEAR(in.t, 1.0f, 2e-3f) << k;  // a 96 x 48 sphere's faces sag 1 - cos(pi / 48) = 2.1e-3 at most
    // From outside, aimed through the centre: the near side's front at 2 - 1.
    const WindingNumber::Hit out = ws.first_hit(d * 2.0f, -d, 0, inf);
    EXPECT_EQ(out.side, -1) << k;
    EXPECT_NEAR(out.t, 1.0f, 2.2e-3f) << k;
  }
}

TEST(WindingNumber, EmptyMeshIsZeroAndBadBetaIsRejected) {
  EXPECT_EQ(WindingNumber()({0, 0, 0}), 0.0);
  const Mesh quad = make_quad({-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1});
  EXPECT_THROW(WindingNumber(quad.positions, quad.indices, 1.0), InputError);
}

TEST(Affine, InverseUndoesTheMap) {
  const Affine3 m{{0.0f, 2.0f, 0.0f}, {-2.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -2.0f}, {1.0f, 2.0f, 3.0f}};  // turn, scale 2, mirror z
  const Affine3 inv = inverse(m);
  for (Vec3 p : {Vec3{0.3f, -1.2f, 4.0f}, Vec3{-7, 0.5f, 2}}) {
    const Vec3 q = inv.point(m.point(p));
    EXPECT_NEAR(q.x, p.x, 1e-5f);
    EXPECT_NEAR(q.y, p.y, 1e-5f);
    EXPECT_NEAR(q.z, p.z, 1e-5f);
  }
}

}  // namespace
}  // namespace ao
