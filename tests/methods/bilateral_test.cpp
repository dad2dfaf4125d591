// SPDX-License-Identifier: Apache-2.0
// The cross-bilateral filter on synthetic G-buffers with known answers: constants stay constant,
// depth discontinuities are not crossed, noise on a plane falls, and bad parameters are refused.
#include "ao/methods/filters/bilateral.h"

#include <gtest/gtest.h>

#include <cmath>

#include <nlohmann/json.hpp>
#include <tbb/global_control.h>

#include "ao/core/error.h"
#include "ao/core/sampling.h"

namespace ao {
namespace {

// Camera-facing planes: pixel (x, y) at depth depth_of(x, y), normal +z, covered unless depth is inf.
template <class DepthFn>
GBuffer facing_planes(int w, int h, DepthFn depth_of) {
  Camera cam;
  cam.width = w;
  cam.height = h;
  GBuffer g(cam);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float d = depth_of(x, y);
      if (!std::isfinite(d)) continue;
      g.position(x, y) = cam.camera_direction(x + 0.5f, y + 0.5f) * d;
      g.normal(x, y) = {0, 0, 1};
      g.object_id(x, y) = 1;
    }
  return g;
}

Image<float> noise(int w, int h, std::uint32_t seed) {
  Image<float> v(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) v(x, y) = to_unit_float(pixel_seed(seed, x, y));
  return v;
}

TEST(Bilateral, ConstantImageStaysConstant) {
  const GBuffer g = facing_planes(64, 48, [](int x, int) { return 3.0f + 0.01f * x; });
  Image<float> v(64, 48, 0.37f);
  bilateral_filter(g, v, {});
  for (std::size_t i = 0; i < v.size(); ++i) EXPECT_NEAR(v[i], 0.37f, 1e-6f) << i;
}

TEST(Bilateral, DoesNotCrossDepthDiscontinuity) {
  // Left half at depth 2, right half at depth 4: the plane distance between them is 2, i.e. 100x
  // the scale (1% of depth); the compact range kernel gives exactly zero weight beyond 2 scales.
  const GBuffer g = facing_planes(64, 48, [](int x, int) { return x < 32 ? 2.0f : 4.0f; });
  Image<float> v(64, 48);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) v(x, y) = x < 32 ? 0.0f : 1.0f;
  const Image<float> before = v;
  bilateral_filter(g, v, {});
  for (std::size_t i = 0; i < v.size(); ++i) EXPECT_EQ(v[i], before[i]) << i;
}

TEST(Bilateral, ReducesNoiseOnAPlane) {
  const GBuffer g = facing_planes(96, 96, [](int, int) { return 5.0f; });
  Image<float> v = noise(96, 96, 7);
  auto variance = [](const Image<float>& img) {
    double s = 0, s2 = 0;
    for (int y = 16; y < 80; ++y)
      for (int x = 16; x < 80; ++x) s += img(x, y), s2 += img(x, y) * img(x, y);
    const double n = 64.0 * 64.0;
    return s2 / n - (s / n) * (s / n);
  };
  const double before = variance(v);
  bilateral_filter(g, v, {});
  // A separable Gaussian of sigma 3.25 px in 2-D averages white noise over ~4 pi sigma^2 = 133 pixels;
  // the 13-tap truncation keeps it above 100. Ask for a factor 50.
  EXPECT_LT(variance(v), before / 50.0);
}

TEST(Bilateral, BackgroundKeepsItsValueAndDoesNotLeakIn) {
  const GBuffer g = facing_planes(40, 30, [](int x, int) { return x < 20 ? 2.0f : kInfinity; });
  Image<float> v(40, 30);
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 40; ++x) v(x, y) = x < 20 ? 0.25f : 1.0f;
  bilateral_filter(g, v, {});
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 40; ++x) EXPECT_NEAR(v(x, y), x < 20 ? 0.25f : 1.0f, 1e-6f) << x << "," << y;
}

TEST(Bilateral, OneTapIsIdentity) {
  const GBuffer g = facing_planes(32, 32, [](int, int) { return 1.0f; });
  Image<float> v = noise(32, 32, 3);
  const Image<float> before = v;
  bilateral_filter(g, v, {.taps = 1});
  for (std::size_t i = 0; i < v.size(); ++i) EXPECT_EQ(v[i], before[i]);
}

TEST(Bilateral, IdenticalAtOneAndTwoThreads) {
  const GBuffer g = facing_planes(700, 40, [](int x, int y) { return 2.0f + 0.003f * x + 0.01f * y; });
  auto run = [&](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
    Image<float> v = noise(700, 40, 11);
    bilateral_filter(g, v, {});
    return v;
  };
  const Image<float> a = run(1), b = run(2);
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << i;
}

TEST(Bilateral, RejectsBadParameters) {
  EXPECT_THROW((BilateralParams{.taps = 12}.validate()), InputError);
  EXPECT_THROW((BilateralParams{.taps = 0}.validate()), InputError);
  EXPECT_THROW((BilateralParams{.taps = 65}.validate()), InputError);
  EXPECT_THROW((BilateralParams{.spatial_sigma = -1}.validate()), InputError);
  EXPECT_THROW((BilateralParams{.plane_sigma = 0}.validate()), InputError);
  const GBuffer g = facing_planes(8, 8, [](int, int) { return 1.0f; });
  Image<float> wrong(4, 4);
  EXPECT_THROW(bilateral_filter(g, wrong, {}), InputError);
  BilateralParams p;
  EXPECT_THROW(from_json(nlohmann::json{{"tap", 3}}, p), InputError);
}

}  // namespace
}  // namespace ao
