// SPDX-License-Identifier: Apache-2.0
#include "ao/core/membership.h"

#include <gtest/gtest.h>

#include "ao/core/error.h"
#include "ao/core/math.h"

namespace ao {
namespace {

const Membership kAll[] = {Membership::Step, Membership::Linear, Membership::Sqrt, Membership::Cubic, Membership::Exp, Membership::Alchemy};

TEST(Membership, StartsAtZeroAndIsOneWhenNothingIsHit) {
  for (Membership m : kAll) {
    const Falloff f{m, 2.0f};
    EXPECT_EQ(f.mu(0.0f), 0.0f) << to_string(m);
    EXPECT_EQ(f.mu(kInfinity), 1.0f) << to_string(m);
  }
}

TEST(Membership, IsMonotoneAndReachesOneAtReach) {
  for (Membership m : kAll) {
    const Falloff f{m, 2.0f};
    float prev = 0;
    for (float d = 0; d < 10; d += 0.01f) {
      EXPECT_GE(f.mu(d), prev) << to_string(m) << " at " << d;
      prev = f.mu(d);
    }
    if (m != Membership::Exp) {
      EXPECT_EQ(f.mu(f.reach()), 1.0f) << to_string(m);
    }
  }
}

TEST(Membership, InverseSamplesHaveCdfMu) {
  // r = mu^-1(xi) with xi uniform has CDF mu: P(r <= d) = mu(d) for d < reach.
  for (Membership m : {Membership::Linear, Membership::Sqrt, Membership::Cubic, Membership::Exp}) {
    const Falloff f{m, 1.5f};
    for (float d : {0.2f, 0.7f, 1.2f}) {
      const int n = 20000;
      int below = 0;
      for (int i = 0; i < n; ++i) below += f.inverse((static_cast<float>(i) + 0.5f) / n) <= d;
      EXPECT_NEAR(static_cast<float>(below) / n, f.mu(d), 1e-3f) << to_string(m) << " at " << d;
    }
  }
  EXPECT_EQ((Falloff{Membership::Step, 1.5f}.inverse(0.3f)), 1.5f);
  // Alchemy with u < R: continuous part max(0, 1 - u/d) below R, an atom of mass u/R at R.
  const Falloff a{Membership::Alchemy, 1.5f, 0.0f, 0.3f};
  for (float d : {0.2f, 0.5f, 1.0f, 1.4f}) {
    const int n = 20000;
    int below = 0;
    for (int i = 0; i < n; ++i) below += a.inverse((static_cast<float>(i) + 0.5f) / n) <= d;
    EXPECT_NEAR(static_cast<float>(below) / n, a.mu(d), 1e-3f) << "alchemy at " << d;
  }
  EXPECT_EQ(a.inverse(0.9f), 1.5f);
}

TEST(Membership, AlchemyIsOneMinusUOverDistanceClippedAtZero) {
  const Falloff f{Membership::Alchemy, 2.0f, 0.0f, 0.5f};
  EXPECT_EQ(f.mu(0.25f), 0.0f);  // g = u/d = 2 is clipped to 1: fully occluded
  EXPECT_FLOAT_EQ(f.mu(1.0f), 0.5f);
  EXPECT_FLOAT_EQ(f.mu(1.999f), 1.0f - 0.5f / 1.999f);
  EXPECT_EQ(f.mu(2.0f), 1.0f);  // H(r - |v|) of eq. 9: nothing beyond R
  EXPECT_EQ(f.reach(), 2.0f);
}

TEST(Membership, AlchemyWithDefaultUIsStep) {
  // u = 0 selects 2R (the paper's sigma = 1 m at r = 0.5 m): u/d >= 2 on [0, R), so every hit inside
  // R occludes fully, exactly as classical AO.
  const Falloff a{Membership::Alchemy, 1.5f}, s{Membership::Step, 1.5f};
  EXPECT_EQ(a.effective_alchemy_u(), 3.0f);
  for (float d = 0; d < 4; d += 0.01f) EXPECT_EQ(a.mu(d), s.mu(d)) << d;
}

TEST(Membership, ExpDefaultTauGivesNinetyFivePercentAtR) {
  const Falloff f{Membership::Exp, 2.0f};
  EXPECT_NEAR(f.mu(2.0f), 1.0f - std::exp(-3.0f), 1e-6f);
  EXPECT_EQ(f.reach(), kInfinity);
}

TEST(Membership, NamesRoundTrip) {
  for (Membership m : kAll) EXPECT_EQ(parse_membership(to_string(m)), m);
  EXPECT_FALSE(parse_membership("cosine").has_value());
}

TEST(Membership, RejectsBadRadiusAndTau) {
  EXPECT_THROW((Falloff{Membership::Step, -1.0f}.validate()), InputError);
  EXPECT_THROW((Falloff{Membership::Step, kInfinity}.validate()), InputError);
  EXPECT_THROW((Falloff{Membership::Exp, 1.0f, -2.0f}.validate()), InputError);
  EXPECT_THROW((Falloff{Membership::Alchemy, 1.0f, 0.0f, -1.0f}.validate()), InputError);
  EXPECT_THROW((Falloff{Membership::Alchemy, 1.0f, 0.0f, kInfinity}.validate()), InputError);
}

}  // namespace
}  // namespace ao
