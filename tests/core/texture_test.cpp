// SPDX-License-Identifier: Apache-2.0
#include "ao/core/texture.h"

#include <gtest/gtest.h>

namespace ao {
namespace {

TEST(Texture, TexelCentresReturnTheirValueWithVUpwards) {
  Image<float> map(2, 2);
  map(0, 0) = 0.1f;  // top-left: u < 0.5, v > 0.5
  map(1, 0) = 0.2f;
  map(0, 1) = 0.3f;  // bottom-left: v < 0.5
  map(1, 1) = 0.4f;
  EXPECT_FLOAT_EQ(sample_bilinear(map, {0.25f, 0.75f}), 0.1f);
  EXPECT_FLOAT_EQ(sample_bilinear(map, {0.75f, 0.75f}), 0.2f);
  EXPECT_FLOAT_EQ(sample_bilinear(map, {0.25f, 0.25f}), 0.3f);
  EXPECT_FLOAT_EQ(sample_bilinear(map, {0.75f, 0.25f}), 0.4f);
}

TEST(Texture, InterpolatesBetweenCentresAndClampsOutside) {
  Image<float> map(2, 1);
  map(0, 0) = 0.0f;
  map(1, 0) = 1.0f;
  EXPECT_FLOAT_EQ(sample_bilinear(map, {0.5f, 0.5f}), 0.5f);
  EXPECT_FLOAT_EQ(sample_bilinear(map, {-3.0f, 0.5f}), 0.0f);
  EXPECT_FLOAT_EQ(sample_bilinear(map, {7.0f, 9.0f}), 1.0f);
}

}  // namespace
}  // namespace ao
