// SPDX-License-Identifier: Apache-2.0
// Reference kinds by name: the registry's matched reference of each method, the names `ao compare
// --reference` and `raytraced -p reference=` accept, and their bad values.
#include "ao/reference/reference.h"

#include <gtest/gtest.h>

#include "ao/core/error.h"
#include "ao/registry/registry.h"
#include "../methods/screen_space_fixtures.h"

namespace ao {
namespace {

ReferenceSpec matched(const char* method, const Falloff& f) {
  const MethodInfo& m = find_method(method);
  return matched_reference(f, m.decode(m.default_params()));
}

TEST(Reference, EachMethodIsJudgedAgainstWhatItEstimates) {
  const Falloff f{Membership::Linear, 2.0f};
  EXPECT_EQ(matched("containment", f).label(), "linear obscurance");
  EXPECT_EQ(matched("volumetric", f).kind, ReferenceKind::TangentSphere);
  EXPECT_EQ(matched("volumetric", f).label(), "tangent sphere");
  EXPECT_EQ(matched("volumetric", f).falloff.radius, 2.0f);
  EXPECT_EQ(matched("transfer", f).kind, ReferenceKind::Transfer);
  EXPECT_EQ(matched("transfer", f).label(), "transfer (linear)");
  EXPECT_EQ(matched("cone", f).label(), "step obscurance");
  // Alchemy: step obscurance within the scene's R (the paper's eq. 3) at any sigma and radius.
  EXPECT_EQ(matched("alchemy", f).label(), "step obscurance");
  EXPECT_EQ(matched("gtao", f).label(), "step obscurance");
}

TEST(Reference, OldReferencesRemainAvailableByName) {
  const Falloff f{Membership::Step, 2.0f};
  const MethodInfo& v = find_method("volumetric");
  EXPECT_EQ(choose_reference("obscurance", f, v.decode(v.default_params())).label(), "cubic obscurance");
  EXPECT_EQ(choose_reference("matched", f, v.decode(v.default_params())).label(), "tangent sphere");
  const MethodInfo& t = find_method("transfer");
  EXPECT_EQ(choose_reference("obscurance", f, t.decode(t.default_params())).label(), "step obscurance");
  nlohmann::json p = t.default_params();
  p["albedo_scale"] = 0.5;
  EXPECT_EQ(choose_reference("transfer", f, t.decode(p)).albedo_scale, 0.5f);
  const MethodInfo& c = find_method("containment");
  EXPECT_EQ(choose_reference("tangent-sphere", f, c.decode(c.default_params())).kind, ReferenceKind::TangentSphere);
  EXPECT_THROW(choose_reference("cubic", f, c.decode(c.default_params())), InputError);
}

TEST(Reference, NamesRoundTrip) {
  for (ReferenceKind k : {ReferenceKind::Obscurance, ReferenceKind::TangentSphere, ReferenceKind::Transfer})
    EXPECT_EQ(parse_reference_kind(to_string(k)), k);
  EXPECT_FALSE(parse_reference_kind("sphere"));
  const ReferenceSpec r1{ReferenceKind::Obscurance, {Membership::Step, 1.0f}}, r2{ReferenceKind::Obscurance, {Membership::Step, 2.0f}};
  EXPECT_NE(r1.key(), r2.key());
  // The tangent sphere has no membership: it does not tell two of them apart.
  const ReferenceSpec s1{ReferenceKind::TangentSphere, {Membership::Step, 1.0f}}, s2{ReferenceKind::TangentSphere, {Membership::Cubic, 1.0f}};
  EXPECT_EQ(s1.key(), s2.key());
}

// `raytraced` renders any kind, chosen by its registry parameter; transfer also gives W in colour
// and the obscurance as an extra.
TEST(Reference, RaytracedRendersEachKindByParameter) {
  const auto s = test::builtin_gbuffer("sphere-on-plane");
  const MethodInfo& m = find_method("raytraced");
  EXPECT_EQ(m.default_params().at(kReferenceParam), "obscurance");
  const Falloff f{Membership::Step, 0.8f};
  for (const char* kind : {"obscurance", "tangent-sphere", "transfer"}) {
    nlohmann::json p = m.default_params();
    p[kReferenceParam] = kind;
    p["samples"] = 8;
    const MethodOutput out = run_method(MethodInput{s.g, s.rays.get(), f, 1}, m.decode(p));
    const RaytracedImage direct = render_reference(*s.rays, s.g, {*parse_reference_kind(kind), f}, {.samples = 8}, 1).scalar;
    for (std::size_t i = 0; i < direct.visibility.size(); ++i) ASSERT_EQ(out.visibility[i], direct.visibility[i]) << kind << ", pixel " << i;
    EXPECT_EQ(!out.color.empty(), std::string(kind) == "transfer") << kind;
    EXPECT_EQ(out.extras.count("obscurance"), std::string(kind) == "transfer" ? 1u : 0u) << kind;
  }
  nlohmann::json bad = m.default_params();
  bad[kReferenceParam] = "cubic";
  EXPECT_THROW(run_method(MethodInput{s.g, s.rays.get(), f, 1}, m.decode(bad)), InputError);
  bad[kReferenceParam] = 3;
  EXPECT_THROW(run_method(MethodInput{s.g, s.rays.get(), f, 1}, m.decode(bad)), InputError);
}

}  // namespace
}  // namespace ao
