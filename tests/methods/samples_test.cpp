// SPDX-License-Identifier: Apache-2.0
// Sample sets: Poisson-disk sets by Lloyd relaxation, containment offsets with r = mu^-1(xi), disk
// samples of volumetric AO, and the interleaving rotations.
#include "ao/methods/samples.h"

#include <gtest/gtest.h>

#include <cmath>

#include "ao/core/error.h"

namespace ao {
namespace {

float min_pairwise_distance(std::span<const Vec3> p) {
  float best = kInfinity;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j) best = std::min(best, length(p[i] - p[j]));
  return best;
}

TEST(Samples, PoissonDiskIsCachedDeterministicAndInsideItsDomain) {
  const auto a = poisson_disk(PoissonDomain::Square, 16);
  const auto b = poisson_disk(PoissonDomain::Square, 16);
  EXPECT_EQ(a.data(), b.data()) << "the second call returns the cached set";
  ASSERT_EQ(a.size(), 16u);
  for (const Vec3& p : a) {
    EXPECT_TRUE(p.x >= 0 && p.x < 1 && p.y >= 0 && p.y < 1 && p.z == 0);
  }
  for (const Vec3& p : poisson_disk(PoissonDomain::Disk, 12)) EXPECT_LT(p.x * p.x + p.y * p.y, 1.0f);
  for (const Vec3& p : poisson_disk(PoissonDomain::Cube, 12)) EXPECT_TRUE(p.x >= 0 && p.x < 1 && p.y >= 0 && p.y < 1 && p.z >= 0 && p.z < 1);
}

TEST(Samples, LloydRelaxationSpreadsPointsApart) {
  // A hexagonal packing of n points in the unit square has spacing ~1.07/sqrt(n); independent
  // uniform points have a minimum distance of order 1/n. Lloyd's centroidal sets reach about 0.8
  // of the hexagonal spacing; 0.5/sqrt(n) separates them clearly from uniform random.
  for (int n : {8, 16, 32}) {
    EXPECT_GT(min_pairwise_distance(poisson_disk(PoissonDomain::Square, n)), 0.5f / std::sqrt(static_cast<float>(n))) << n;
  }
}

TEST(Samples, ContainmentOffsetsFollowTheMembership) {
  const Falloff cubic{Membership::Cubic, 2.0f};
  const ContainmentSamples s = make_containment_samples(64, cubic);
  ASSERT_EQ(s.size(), 64);
  double mean_r = 0, mean_cos = 0;
  for (int i = 0; i < s.size(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    EXPECT_GE(s.z[k], 0.0f) << "offsets lie in the hemisphere about N";
    EXPECT_NEAR(std::sqrt(s.x[k] * s.x[k] + s.y[k] * s.y[k] + s.z[k] * s.z[k]), s.r[k], 1e-5f);
    EXPECT_LE(s.r[k], 2.0f);
    mean_r += s.r[k];
    mean_cos += s.z[k] / s.r[k];
  }
  // Density dmu/dr = 3 r^2 / R^3 has mean 3R/4 = 1.5; cosine-weighted directions have mean
  // cos(theta) 2/3. Stratified (Poisson-disk) samples of 64 points land within a few percent.
  EXPECT_NEAR(mean_r / 64, 1.5, 0.05);
  EXPECT_NEAR(mean_cos / 64, 2.0 / 3.0, 0.03);
  // Step: every sample at distance R (the derivative of the step is a Dirac delta at R).
  for (float r : make_containment_samples(8, {Membership::Step, 3.0f}).r) EXPECT_FLOAT_EQ(r, 3.0f);
}

TEST(Samples, DiskSamplesEstimateTheSphereVolume) {
  // Volumetric AO's F = R sum h_i estimates |S| / (R^2 pi / 4n) = 2Rn/3: sum h_i / n -> 2/3.
  // Lloyd's sites are cell centroids, pulled inside the disk, where h is larger: small sets
  // overestimate (0.80 at n = 4), which is exactly the error WIS cancels in eq. 7's ratio.
  float previous = 1;
  for (int n : {4, 8, 16, 32, 128}) {
    const DiskSamples s = make_disk_samples(n);
    float sum = 0;
    for (float h : s.h) sum += h;
    EXPECT_GT(sum / n, 2.0f / 3.0f - 0.01f) << n;
    EXPECT_LT(sum / n, previous) << n;
    previous = sum / n;
  }
  EXPECT_NEAR(previous, 2.0f / 3.0f, 0.02f) << "n = 128";
}

TEST(Samples, InterleaveRotationsAreSixteenDistinctAnglesOrOne) {
  const auto r = interleave_rotations(7, true);
  for (int i = 0; i < 16; ++i) {
    EXPECT_NEAR(r[i].c * r[i].c + r[i].s * r[i].s, 1.0f, 1e-5f);
    for (int j = i + 1; j < 16; ++j) EXPECT_GT(std::abs(r[i].c - r[j].c) + std::abs(r[i].s - r[j].s), 1e-4f);
  }
  const auto same = interleave_rotations(7, false);
  for (int i = 1; i < 16; ++i) EXPECT_EQ(same[i].c, same[0].c);
  const auto again = interleave_rotations(7, true);
  for (int i = 0; i < 16; ++i) EXPECT_EQ(again[i].c, r[i].c) << "deterministic for a seed";
}

TEST(Samples, RejectsBadCounts) {
  EXPECT_THROW(poisson_disk(PoissonDomain::Disk, 0), InputError);
  EXPECT_THROW(poisson_disk(PoissonDomain::Disk, kMaxScreenSpaceSamples + 1), InputError);
}

}  // namespace
}  // namespace ao
