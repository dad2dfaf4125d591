// SPDX-License-Identifier: Apache-2.0
#include "ao/eval/metrics.h"

#include <gtest/gtest.h>

#include <cmath>

#include "ao/core/error.h"

namespace ao {
namespace {

Image<float> ramp(int w, int h) {
  Image<float> img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img(x, y) = static_cast<float>(x + y) / static_cast<float>(w + h);
  return img;
}

TEST(Metrics, IdenticalImagesHaveZeroErrorAndUnitSsim) {
  const Image<float> a = ramp(32, 24);
  const ErrorMetrics m = compare_images(a, a);
  EXPECT_EQ(m.rmse, 0.0);
  EXPECT_TRUE(std::isinf(m.psnr_db));
  EXPECT_NEAR(m.ssim, 1.0, 1e-12);
  EXPECT_EQ(m.pixels, 32u * 24u);
}

TEST(Metrics, ConstantOffsetGivesKnownRmsePsnrAndSignedError) {
  const Image<float> a = ramp(32, 24);
  Image<float> b = a;
  for (float& v : b.pixels()) v += 0.1f;
  const ErrorMetrics m = compare_images(b, a);
  EXPECT_NEAR(m.rmse, 0.1, 1e-6);
  EXPECT_NEAR(m.psnr_db, 20.0, 1e-4);  // 10 log10(1 / 0.01)
  EXPECT_NEAR(m.mean_signed, 0.1, 1e-6);
  EXPECT_LT(m.ssim, 1.0);
}

TEST(Metrics, MaskExcludesPixels) {
  Image<float> a(4, 1, 0.5f), b(4, 1, 0.5f);
  b(3, 0) = 0.0f;
  Image<std::uint8_t> mask(4, 1, 1);
  mask(3, 0) = 0;
  EXPECT_EQ(compare_images(b, a, mask).rmse, 0.0);
  EXPECT_EQ(compare_images(b, a, mask).pixels, 3u);
  EXPECT_NEAR(compare_images(b, a).rmse, 0.25, 1e-7);
}

TEST(Metrics, NoiseLowersSsimMoreThanItsMeanSuggests) {
  const Image<float> a = ramp(64, 64);
  Image<float> noisy = a;
  for (std::size_t i = 0; i < noisy.size(); ++i) noisy[i] += (i % 2 ? 0.05f : -0.05f);
  const ErrorMetrics m = compare_images(noisy, a);
  EXPECT_NEAR(m.mean_signed, 0.0, 1e-6);
  EXPECT_LT(m.ssim, 0.9);
}

TEST(Metrics, HeatMapIsWhiteWhereEqualRedWhereBrighterBlueWhereDarker) {
  Image<float> ref(3, 1, 0.5f), img(3, 1, 0.5f);
  img(1, 0) = 1.0f;
  img(2, 0) = 0.0f;
  const Image<Vec3> heat = signed_error_heat_map(img, ref, {}, 0.5f);
  EXPECT_EQ(heat(0, 0), (Vec3{1, 1, 1}));
  EXPECT_EQ(heat(1, 0), (Vec3{1, 0, 0}));
  EXPECT_EQ(heat(2, 0), (Vec3{0, 0, 1}));
}

TEST(Metrics, RejectsSizeMismatch) { EXPECT_THROW(compare_images(Image<float>(2, 2), Image<float>(3, 2)), InputError); }

}  // namespace
}  // namespace ao
