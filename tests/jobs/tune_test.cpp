// SPDX-License-Identifier: Apache-2.0
// Parameter fitting (eval/tune.h): a known optimum found, improvement over the start, and bad input.
#include "ao/jobs/tune.h"

#include <gtest/gtest.h>

#include <cmath>

#include "ao/core/error.h"
#include "ao/eval/metrics.h"
#include "ao/registry/registry.h"
#include "../methods/screen_space_fixtures.h"

namespace ao {
namespace {

// The target is transfer's own output at albedo_scale = 0.4, so the mean RMSE is 0 there and grows
// on either side (W is monotone in the albedo): starting at 1, the descent must find 0.4 to within
// its final step, min_step x range = 1e-3, plus one step of slack.
TEST(Tune, FindsAKnownOptimum) {
  const auto s = test::builtin_gbuffer("sphere-on-plane");
  const Falloff f{Membership::Step, 0.8f};
  const MethodInfo& m = find_method("transfer");
  nlohmann::json target = m.default_params();
  target["albedo_scale"] = 0.4;
  TuneView view{s.rays.get(), &s.g, &s.scene.analytic, f, run_method(MethodInput{s.g, s.rays.get(), f, 1}, m.decode(target)).visibility};
  TuneSettings settings{.method = "transfer", .parameters = {{"albedo_scale", 0.0, 1.0}}, .time_budget_s = 120};
  const TuneResult r = tune_method({view}, settings);
  EXPECT_NEAR(r.params.at("albedo_scale").get<double>(), 0.4, 2e-3);
  EXPECT_LT(r.best_rmse, 1e-3);
  EXPECT_GT(r.start_rmse, 0.01);
  EXPECT_GT(r.evaluations, 2);
}

// Alchemy's intensity (sigma) fitted to its matched reference on two views: never worse than the
// start, within the range, and the same result again (deterministic).
TEST(Tune, AlchemyIntensityImprovesAndIsDeterministic) {
  const auto a = test::builtin_gbuffer("sphere-on-plane"), b = test::builtin_gbuffer("wedge");
  const MethodInfo& m = find_method("alchemy");
  std::vector<TuneView> views;
  for (const auto* s : {&a, &b}) {
    const Falloff f{Membership::Step, 0.8f};
    views.push_back({s->rays.get(), &s->g, nullptr, f,
                     render_reference(*s->rays, s->g, matched_reference(f, m.decode(m.default_params())), {.samples = 64}, 2).scalar.visibility});
  }
  TuneSettings settings{.method = "alchemy", .parameters = {{"intensity", 0.05, 2.0}}, .time_budget_s = 60, .min_step = 1e-2};
  const TuneResult r1 = tune_method(views, settings), r2 = tune_method(views, settings);
  EXPECT_LE(r1.best_rmse, r1.start_rmse);
  const double x = r1.params.at("intensity").get<double>();
  EXPECT_GE(x, 0.05);
  EXPECT_LE(x, 2.0);
  EXPECT_EQ(r1.params, r2.params);
  EXPECT_EQ(r1.best_rmse, r2.best_rmse);
}

// An unset value starts where the method's preset puts it (Alchemy's fitted sigma 0.4), whatever the
// range: with no time for a move the result is the start.
TEST(Tune, StartsFromThePresetsValueNotTheMiddleOfTheRange) {
  const auto s = test::builtin_gbuffer("sphere-on-plane");
  const TuneView view{s.rays.get(), &s.g, nullptr, {Membership::Step, 0.8f}, Image<float>(s.g.width(), s.g.height(), 1.0f)};
  for (const auto& [lo, hi] : {std::pair{0.1, 2.0}, std::pair{0.3, 0.5}}) {
    const TuneResult r = tune_method({view}, {.method = "alchemy", .parameters = {{"intensity", lo, hi}}, .time_budget_s = 1e-9});
    EXPECT_EQ(r.evaluations, 1);
    EXPECT_DOUBLE_EQ(r.params.at("intensity").get<double>(), 0.4) << lo << ":" << hi;
  }
  nlohmann::json paper = find_method("alchemy").default_params();
  paper["preset"] = "paper";
  const TuneResult r = tune_method({view}, {.method = "alchemy", .start = paper, .parameters = {{"intensity", 0.1, 2.0}}, .time_budget_s = 1e-9});
  EXPECT_DOUBLE_EQ(r.params.at("intensity").get<double>(), 1.0);
  // A start outside the range begins at its nearest end.
  const TuneResult c = tune_method({view}, {.method = "alchemy", .parameters = {{"intensity", 0.6, 2.0}}, .time_budget_s = 1e-9});
  EXPECT_DOUBLE_EQ(c.params.at("intensity").get<double>(), 0.6);
}

// Alchemy's radius 0 means the falloff radius R: a fit of it starts at R (the default's own result,
// the same image), not at the range's end.
TEST(Tune, AlchemysRadiusStartsAtTheFalloffRadius) {
  const auto s = test::builtin_gbuffer("sphere-on-plane");
  const Falloff f{Membership::Step, 0.8f};
  const MethodInfo& m = find_method("alchemy");
  const TuneView view{s.rays.get(), &s.g, nullptr, f, Image<float>(s.g.width(), s.g.height(), 1.0f)};
  const TuneResult r = tune_method({view}, {.method = "alchemy", .parameters = {{"radius", 0.2, 2.0}}, .time_budget_s = 1e-9});
  EXPECT_EQ(r.evaluations, 1);
  EXPECT_DOUBLE_EQ(r.params.at("radius").get<double>(), 0.8);
  const Image<std::uint8_t> covered = coverage_mask(s.g);
  const double at_default = compare_images(run_method(MethodInput{s.g, s.rays.get(), f, 1}, m.decode(m.default_params())).visibility, view.reference, covered).rmse;
  EXPECT_EQ(r.start_rmse, at_default);
}

// The optimum (albedo_scale = 0.4, as in FindsAKnownOptimum) lies below the range asked for: the
// fit ends at the lower end and says so; inside the range it does not.
TEST(Tune, SaysWhenTheResultIsAtAnEndOfItsRange) {
  const auto s = test::builtin_gbuffer("sphere-on-plane");
  const Falloff f{Membership::Step, 0.8f};
  const MethodInfo& m = find_method("transfer");
  nlohmann::json target = m.default_params();
  target["albedo_scale"] = 0.4;
  TuneView view{s.rays.get(), &s.g, &s.scene.analytic, f, run_method(MethodInput{s.g, s.rays.get(), f, 1}, m.decode(target)).visibility};
  const TuneResult below = tune_method({view}, {.method = "transfer", .parameters = {{"albedo_scale", 0.6, 1.0}}, .time_budget_s = 120});
  EXPECT_DOUBLE_EQ(below.params.at("albedo_scale").get<double>(), 0.6);
  EXPECT_EQ(below.on_bound, std::vector<std::string>{"albedo_scale"});
  const TuneResult inside = tune_method({view}, {.method = "transfer", .parameters = {{"albedo_scale", 0.0, 1.0}}, .time_budget_s = 120});
  EXPECT_TRUE(inside.on_bound.empty()) << inside.params.at("albedo_scale");
}

TEST(Tune, RejectsBadSettings) {
  const auto s = test::builtin_gbuffer("plane");
  const TuneView view{s.rays.get(), &s.g, nullptr, {Membership::Step, 1.0f}, Image<float>(s.g.width(), s.g.height(), 1.0f)};
  auto tune = [&](TuneSettings t) { return tune_method({view}, t); };
  EXPECT_THROW(tune({.method = "nonsense", .parameters = {{"samples", 1, 8}}}), InputError);
  EXPECT_THROW(tune({.method = "alchemy", .parameters = {{"sigma", 0, 1}}}), InputError);      // no such key
  EXPECT_THROW(tune({.method = "alchemy", .parameters = {{"filter", 0, 1}}}), InputError);     // not a number
  EXPECT_THROW(tune({.method = "alchemy", .parameters = {{"intensity", 1, 1}}}), InputError);  // empty range
  EXPECT_THROW(tune({.method = "alchemy", .parameters = {}}), InputError);
  EXPECT_THROW(tune_method({}, {.method = "alchemy", .parameters = {{"intensity", 0, 1}}}), InputError);
}

}  // namespace
}  // namespace ao
