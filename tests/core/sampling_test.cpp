// SPDX-License-Identifier: Apache-2.0
#include "ao/core/sampling.h"
#include "ao/simd/sampling_internal.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <set>

namespace ao {
namespace {

TEST(Sampling, SobolPrefixIsStratifiedInEveryElementaryInterval) {
  // A (0,2)-sequence: any 2^k consecutive-from-zero points put exactly one point in each cell of
  // every 2^a x 2^b grid with a + b = k. Owen scrambling preserves this.
  const int k = 8, n = 1 << k;
  for (std::uint32_t seed : {0u, 1u, 12345u}) {
    for (int a = 0; a <= k; ++a) {
      const int cols = 1 << a, rows = 1 << (k - a);
      std::set<int> cells;
      for (int i = 0; i < n; ++i) {
        const Vec2 u = sobol_owen_2d(static_cast<std::uint32_t>(i), seed);
        ASSERT_GE(u.x, 0.0f);
        ASSERT_LT(u.x, 1.0f);
        cells.insert(static_cast<int>(u.x * cols) * rows + static_cast<int>(u.y * rows));
      }
      EXPECT_EQ(cells.size(), static_cast<std::size_t>(n)) << "seed " << seed << ", grid " << cols << "x" << rows;
    }
  }
}

// The definition, written out plainly: Burley's nested uniform scramble of the index, Sobol's first
// two dimensions (bit reversal; the direction numbers of x + 1 XORed over the index's set bits),
// each scrambled again. sobol_owen_2d computes the same bits with fewer reversals and tables.
std::uint32_t reverse32(std::uint32_t x) {
  std::uint32_t r = 0;
  for (int b = 0; b < 32; ++b) r |= ((x >> b) & 1u) << (31 - b);
  return r;
}
std::uint32_t owen(std::uint32_t x, std::uint32_t seed) {
  x = reverse32(x) + seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return reverse32(x);
}
std::uint32_t sobol1(std::uint32_t i) {
  std::uint32_t r = 0, v = 1u << 31;
  for (int b = 0; b < 32; ++b, v ^= v >> 1)
    if (i >> b & 1u) r ^= v;
  return r;
}

TEST(Sampling, SobolOwenIsTheDefinitionBitForBit) {
  for (std::uint32_t seed : {0u, 1u, 7u, 0xdeadbeefu})
    for (std::uint32_t i : {0u, 1u, 2u, 3u, 63u, 64u, 1000u, 65535u, 0x12345678u, 0xffffffffu}) {
      const std::uint32_t s = owen(i, hash_combine(seed, 0xa511e9b3u));
      const Vec2 u = sobol_owen_2d(i, seed);
      EXPECT_EQ(u.x, to_unit_float(owen(reverse32(s), hash_combine(seed, 1u)))) << i << " " << seed;
      EXPECT_EQ(u.y, to_unit_float(owen(sobol1(s), hash_combine(seed, 2u)))) << i << " " << seed;
    }
}

TEST(Sampling, Sobol4dPrefixIsStratifiedInEachDimensionAndInTheFirstPair) {
  // Dimensions 0-1 of the first 2^k points form a (0,k,2)-net; each of the four dimensions alone
  // puts one point in each of 2^k equal intervals (wrong direction numbers, such as an even
  // initial m, break this). Owen scrambling preserves both.
  const int k = 8, n = 1 << k;
  for (std::uint32_t seed : {0u, 1u, 12345u}) {
    for (int a = 0; a <= k; ++a) {
      const int cols = 1 << a, rows = 1 << (k - a);
      std::set<int> cells;
      for (int i = 0; i < n; ++i) {
        const std::array<float, 4> u = sobol_owen_4d(static_cast<std::uint32_t>(i), seed);
        cells.insert(static_cast<int>(u[0] * cols) * rows + static_cast<int>(u[1] * rows));
      }
      EXPECT_EQ(cells.size(), static_cast<std::size_t>(n)) << "seed " << seed << ", grid " << cols << "x" << rows;
    }
    for (int d = 0; d < 4; ++d) {
      std::set<int> strata;
      for (int i = 0; i < n; ++i) {
        const float u = sobol_owen_4d(static_cast<std::uint32_t>(i), seed)[static_cast<std::size_t>(d)];
        ASSERT_GE(u, 0.0f);
        ASSERT_LT(u, 1.0f);
        strata.insert(static_cast<int>(u * n));
      }
      EXPECT_EQ(strata.size(), static_cast<std::size_t>(n)) << "seed " << seed << ", dimension " << d;
    }
  }
}

TEST(Sampling, Sobol4dIntegratesAProductOfAllFourDimensions) {
  // The integral of x0 x1 x2 x3 over [0,1]^4 is 1/16. A jointly stratified set gets it to ~1e-4 at
  // 4096 points; dimensions paired at random (independent sets) leave the MC error of
  // sd(x0 x1 x2 x3) / 64 = 0.0012 (sd^2 = 1/81 - 1/256).
  for (std::uint32_t seed : {3u, 4u, 5u}) {
    double sum = 0;
    const int n = 4096;
    for (int i = 0; i < n; ++i) {
      const std::array<float, 4> u = sobol_owen_4d(static_cast<std::uint32_t>(i), seed);
      sum += static_cast<double>(u[0]) * u[1] * u[2] * u[3];
    }
    EXPECT_NEAR(sum / n, 1.0 / 16.0, 3e-4) << "seed " << seed;
  }
}

TEST(Sampling, Sobol4dBatchIsBitIdenticalToOnePointAtATime) {
  // Both batch paths: a first index that is a multiple of 16 (the XOR of two table points) and one
  // that is not (each point on its own), with a full and a partial batch.
  for (std::uint32_t seed : {0u, 7u, 0xdeadbeefu})
    for (std::uint32_t first : {0u, 16u, 48u, 4080u, 65520u, 3u, 1000001u})
      for (int count : {16, 5}) {
        float out[4][16];
        sobol_owen_4d_batch(first, count, seed, out);
        for (int k = 0; k < count; ++k) {
          const std::array<float, 4> u = sobol_owen_4d(first + static_cast<std::uint32_t>(k), seed);
          for (int d = 0; d < 4; ++d) EXPECT_EQ(out[d][k], u[static_cast<std::size_t>(d)]) << "seed " << seed << " point " << first + k << " dim " << d;
        }
      }
}

TEST(Sampling, DifferentSeedsGiveDifferentPoints) {
  EXPECT_NE(sobol_owen_2d(3, 1).x, sobol_owen_2d(3, 2).x);
  EXPECT_EQ(sobol_owen_2d(3, 1).x, sobol_owen_2d(3, 1).x);
}

TEST(Sampling, CosineHemisphereHasCosineDensity) {
  // E[cos theta] under pdf cos/pi is 2/3; E[cos^2] is 1/2. Every direction is a unit vector with z >= 0.
  const int n = 1 << 14;
  double m1 = 0, m2 = 0;
  for (int i = 0; i < n; ++i) {
    const Vec3 d = cosine_hemisphere(sobol_owen_2d(static_cast<std::uint32_t>(i), 7));
    ASSERT_NEAR(length(d), 1.0f, 1e-5f);
    ASSERT_GE(d.z, 0.0f);
    m1 += d.z;
    m2 += d.z * d.z;
  }
  EXPECT_NEAR(m1 / n, 2.0 / 3.0, 1e-3);
  EXPECT_NEAR(m2 / n, 0.5, 1e-3);
}

TEST(Sampling, UniformSphereHasZeroMeanAndUnitLength) {
  const int n = 1 << 14;
  Vec3 sum{};
  for (int i = 0; i < n; ++i) {
    const Vec3 d = uniform_sphere(sobol_owen_2d(static_cast<std::uint32_t>(i), 3));
    ASSERT_NEAR(length(d), 1.0f, 1e-5f);
    sum += d;
  }
  EXPECT_NEAR(length(sum) / n, 0.0f, 2e-3f);
}

TEST(Sampling, FrameIsOrthonormalForAnyNormal) {
  for (Vec3 n : {Vec3{0, 0, 1}, Vec3{0, 0, -1}, Vec3{1, 0, 0}, normalize(Vec3{1, -2, 3}), normalize(Vec3{1e-8f, 0, -1})}) {
    const Frame f = Frame::from_normal(n);
    EXPECT_NEAR(dot(f.t, f.b), 0.0f, 1e-6f);
    EXPECT_NEAR(dot(f.t, f.n), 0.0f, 1e-6f);
    EXPECT_NEAR(dot(f.b, f.n), 0.0f, 1e-6f);
    EXPECT_NEAR(length(f.t), 1.0f, 1e-6f);
    EXPECT_NEAR(length(f.b), 1.0f, 1e-6f);
    // Right-handed: t x b = n.
    EXPECT_NEAR(length(cross(f.t, f.b) - n), 0.0f, 1e-5f);
  }
}

}  // namespace
}  // namespace ao
