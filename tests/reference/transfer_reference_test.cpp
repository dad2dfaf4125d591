// SPDX-License-Identifier: Apache-2.0
// The ambient transfer reference (AT eq. 6, ray-traced) against known answers: the open plane, the
// white room (albedo 1: W = 1 however closed, AT sec. 3's "corners of white rooms will not be darker
// than the wall itself"), and an empty room of coloured walls where both integrals of eq. 6 come
// from a deterministic quadrature with exact distances to the walls. Tolerances: 4 reported
// standard errors (see raytraced_test.cpp) plus 1e-3 for the quadrature and the ray offset.
#include "ao/reference/transfer_reference.h"

#include <gtest/gtest.h>

#include <cmath>

#include <tbb/global_control.h>

#include "ao/core/error.h"
#include "ao/core/sampling.h"
#include "ao/registry/registry.h"
#include "ao/scene/procedural.h"
#include "../methods/screen_space_fixtures.h"
#include "../support/scenes.h"

namespace ao {
namespace {

constexpr float kSigmas = 4.0f;
constexpr Vec3 kLo{-2, 0, -2.5f}, kHi{2, 3, 2.5f};  // the box-room's room

Scene room_of_albedo(Vec3 albedo) { return test::scene_of({make_box(kLo, kHi, albedo, 0.0f, true)}); }

// Distance from p inside the room to its walls along unit direction w.
float distance_to_walls(Vec3 p, Vec3 w) {
  float d = kInfinity;
  for (int i = 0; i < 3; ++i) {
    if (w[i] > 0) d = std::min(d, (kHi[i] - p[i]) / w[i]);
    if (w[i] < 0) d = std::min(d, (kLo[i] - p[i]) / w[i]);
  }
  return d;
}

// Eq. 6 at p on the floor (normal +y) by a midpoint rule over a 512 x 512 grid of the
// cosine-weighted map: O = mean mu(D), L_c = mean (1 - mu(D)) a_c, W_c = O / (1 - L_c).
Vec3 quadrature_transfer(Vec3 p, const Falloff& f, Vec3 a, double* obscurance) {
  constexpr int kN = 512;
  const Frame frame = Frame::from_normal({0, 1, 0});
  double o = 0, l = 0;
  for (int i = 0; i < kN; ++i)
    for (int j = 0; j < kN; ++j) {
      const Vec3 w = frame.to_world(cosine_hemisphere({(i + 0.5f) / kN, (j + 0.5f) / kN}));
      const double mu = f.mu(distance_to_walls(p, w));
      o += mu;
      l += 1.0 - mu;
    }
  o /= kN * kN;
  l /= kN * kN;
  *obscurance = o;
  return {static_cast<float>(o / (1 - l * a.x)), static_cast<float>(o / (1 - l * a.y)), static_cast<float>(o / (1 - l * a.z))};
}

TEST(TransferReference, OpenPlaneIsFullyVisible) {
  const Scene s = make_builtin_scene("plane");
  const RayScene rs(s);
  const TransferEstimate e = estimate_transfer(rs, {0.3f, 0, -1.2f}, {0, 1, 0}, {Membership::Linear, 2.0f}, 1.0f, {.samples = 256}, 7);
  EXPECT_EQ(e.transfer, (Vec3{1, 1, 1}));
  EXPECT_EQ(e.luminance, 1.0f);
  EXPECT_EQ(e.obscurance, 1.0f);
  EXPECT_EQ(e.std_error, 0.0f);
}

// White walls return all the light they receive: W = O / (1 - (1 - O)) = 1 at every point, though
// the room is closed and O < 1 (R larger than the room: O = mean d / R).
TEST(TransferReference, WhiteRoomIsUniformlyLit) {
  Scene s = make_builtin_scene("box-room");
  for (Mesh& m : s.meshes) m.albedo = {1, 1, 1};
  const auto sg = test::scene_gbuffer(std::move(s));
  const TransferReferenceImage img = render_transfer_reference(*sg.rays, sg.g, {Membership::Linear, 20.0f}, 1.0f, {.samples = 64}, 3);
  for (std::size_t i = 0; i < img.transfer.size(); ++i) {
    if (!sg.g.covered(i)) continue;
    ASSERT_LT(img.obscurance[i], 0.5f) << "pixel " << i;
    ASSERT_NEAR(img.scalar.visibility[i], 1.0f, 1e-5f) << "pixel " << i;  // float rounding of the ratio
  }
}

// Coloured walls, linear membership with R = 10 (larger than the room, so every direction sees a
// wall at distance < R): each channel of W against the quadrature of eq. 6.
TEST(TransferReference, ColouredRoomMatchesTheQuadratureOfEquation6) {
  const Vec3 albedo{0.9f, 0.5f, 0.1f};
  const Scene s = room_of_albedo(albedo);
  const RayScene rs(s);
  const Falloff f{Membership::Linear, 10.0f};
  for (Vec3 p : {Vec3{0.3f, 0, -0.4f}, Vec3{1.9f, 0, 2.4f}}) {
    double o = 0;
    const Vec3 expected = quadrature_transfer(p, f, albedo, &o);
    const TransferEstimate e = estimate_transfer(rs, p, {0, 1, 0}, f, 1.0f, {.samples = 4096}, 13);
    const double tol = kSigmas * e.std_error + 1e-3;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(e.transfer[c], expected[c], tol) << "channel " << c;
    EXPECT_NEAR(e.obscurance, o, tol);
    EXPECT_GT(e.transfer.x, e.transfer.z);  // more light bounces off the redder walls
    EXPECT_NEAR(e.luminance, 0.2126f * e.transfer.x + 0.7152f * e.transfer.y + 0.0722f * e.transfer.z, 1e-5f);
  }
}

// Black occluders (or albedo scale 0) reflect nothing: W = O exactly, and O estimates the
// obscurance reference of the same membership (own sample sets: the means agree within their
// standard errors).
TEST(TransferReference, BlackOccludersGiveTheObscuranceReference) {
  const auto s = test::builtin_gbuffer("sphere-on-plane");
  const Falloff f{Membership::Linear, 0.8f};
  const TransferReferenceImage t = render_transfer_reference(*s.rays, s.g, f, 0.0f, {.samples = 64}, 4);
  const RaytracedImage o = render_raytraced(*s.rays, s.g, f, {.samples = 64}, 4);
  double sum_t = 0, sum_o = 0, var = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < o.visibility.size(); ++i) {
    ASSERT_EQ(t.scalar.visibility[i], t.obscurance[i]) << "pixel " << i;
    if (!s.g.covered(i)) continue;
    sum_t += t.obscurance[i];
    sum_o += o.visibility[i];
    var += static_cast<double>(o.std_error[i]) * o.std_error[i];
    ++n;
  }
  ASSERT_GT(n, 0u);
  // Two independent estimates of the same mean: 4 combined standard errors of the pixel mean.
  EXPECT_NEAR(sum_t / n, sum_o / n, 4.0 * std::sqrt(2.0 * var) / n + 1e-4);
}

TEST(TransferReference, IndependentOfThreadCountAndAtLeastTheObscurance) {
  const auto s = test::builtin_gbuffer("box-room");
  auto render = [&](int threads) {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, threads);
    return render_transfer_reference(*s.rays, s.g, {Membership::Step, 1.0f}, 1.0f, {.samples = 32}, 4);
  };
  const TransferReferenceImage a = render(1), b = render(2);
  for (std::size_t i = 0; i < a.transfer.size(); ++i) {
    ASSERT_EQ(a.transfer[i], b.transfer[i]) << "pixel " << i;
    ASSERT_GE(a.scalar.visibility[i], a.obscurance[i] - 1e-6f) << "pixel " << i;
    ASSERT_LE(a.scalar.visibility[i], 1.0f) << "pixel " << i;
  }
}

// Where every surface has one albedo, the receiver's is every occluder's: the two references are the
// same image, bit for bit (the same rays; the G-buffer carries the meshes' albedo exactly).
TEST(TransferReference, ReceiverAlbedoIsTheOccludersWhereAllShareOne) {
  Scene scene = make_builtin_scene("box-room");
  for (Mesh& m : scene.meshes) m.albedo = {0.7f, 0.5f, 0.3f};
  const auto s = test::scene_gbuffer(std::move(scene));
  const Falloff f{Membership::Step, 1.0f};
  const TransferReferenceImage own = render_transfer_reference(*s.rays, s.g, f, 0.8f, {.samples = 32}, 4);
  const TransferReferenceImage receiver = render_transfer_reference(*s.rays, s.g, f, 0.8f, {.samples = 32}, 4, {}, TransferAlbedo::Receiver);
  for (std::size_t i = 0; i < own.transfer.size(); ++i) ASSERT_EQ(own.transfer[i], receiver.transfer[i]) << "pixel " << i;
}

// The receiver's albedo is read from the G-buffer: one rendered without it is refused, not read as black.
TEST(TransferReference, ReceiverAlbedoNeedsTheGBuffersAlbedo) {
  const auto s = test::builtin_gbuffer("box-room");
  GBuffer g = s.g;
  g.albedo = Image<Vec3>();
  EXPECT_THROW(render_transfer_reference(*s.rays, g, {Membership::Step, 1.0f}, 1.0f, {.samples = 4}, 4, {}, TransferAlbedo::Receiver), InputError);
}

TEST(TransferReference, RejectsBadAlbedoScale) {
  const Scene s = make_builtin_scene("plane");
  const RayScene rs(s);
  EXPECT_THROW(estimate_transfer(rs, {0, 0, 0}, {0, 1, 0}, {Membership::Step, 1.0f}, 1.5f, {}, 1), InputError);
  EXPECT_THROW(estimate_transfer(rs, {0, 0, 0}, {0, 1, 0}, {Membership::Step, 1.0f}, -0.1f, {}, 1), InputError);
}

}  // namespace
}  // namespace ao
