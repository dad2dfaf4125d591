// SPDX-License-Identifier: Apache-2.0
// Every method of the registry through the same checks, so that a new row is tested without a
// line here: the open plane is fully visible, V stays in [0, 1], results are identical at 1 and 2
// threads, the mean V falls as R grows, parameters round trip through JSON (floats at the
// precision they were given), bad parameter values are refused with one line that names the
// parameter and its valid range, and no reference moves when an estimator parameter changes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>
#include <tbb/global_control.h>

#include "ao/core/error.h"
#include "ao/core/params.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/registry/registry.h"
#include "ao/scene/procedural.h"

namespace ao {
namespace {

struct Fixture {
  Scene scene;
  std::unique_ptr<RayScene> rays;
  GBuffer g;
};

// A built-in scene's G-buffer from its preferred view at 64 x 40 (small: every method runs on it
// several times).
Fixture fixture(const char* name) {
  Fixture f{make_builtin_scene(name), nullptr, {}};
  f.rays = std::make_unique<RayScene>(f.scene);
  Camera c = *f.scene.preferred_view;
  c.width = 64;
  c.height = 40;
  f.g = render_gbuffer(*f.rays, c);
  return f;
}

MethodOutput run(const MethodInfo& m, const Fixture& f, const Falloff& falloff, std::uint32_t seed = 3) {
  return run_method(MethodInput{f.g, f.rays.get(), falloff, seed, {}, &f.scene.analytic}, m.decode(m.default_params()));
}

class AllMethods : public ::testing::TestWithParam<std::string> {
 protected:
  const MethodInfo& method() const { return find_method(GetParam()); }
};

TEST_P(AllMethods, OpenPlaneIsFullyVisible) {
  const Fixture f = fixture("plane");
  const MethodOutput out = run(method(), f, {Membership::Step, 2.0f});
  // Not exactly 1 for every method: volumetric AO's pipes run along the camera's z axis but read z*
  // along the view ray through their middle, a perspective error of order R / depth (at most 0.01
  // here, volumetric_test.cpp); the others are 1 up to float rounding. Each method's own test
  // checks its exact answer.
  double sum = 0;
  for (std::size_t i = 0; i < out.visibility.size(); ++i) {
    ASSERT_GE(out.visibility[i], 0.99f) << "pixel " << i;
    ASSERT_LE(out.visibility[i], 1.0f + 1e-6f) << "pixel " << i;  // float rounding of transfer's luminance of W
    sum += out.visibility[i];
  }
  EXPECT_GT(sum / static_cast<double>(out.visibility.size()), 0.999);
}

TEST_P(AllMethods, VisibilityInUnitIntervalAndIdenticalAtOneAndTwoThreads) {
  const Fixture f = fixture("default");
  const Falloff falloff{Membership::Linear, 0.1f * f.scene.bounds().diagonal()};
  auto at = [&](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
    return run(method(), f, falloff, 42);
  };
  const MethodOutput a = at(1), b = at(2);
  double sum = 0;
  for (std::size_t i = 0; i < a.visibility.size(); ++i) {
    ASSERT_EQ(a.visibility[i], b.visibility[i]) << "pixel " << i;
    ASSERT_GE(a.visibility[i], 0.0f) << "pixel " << i;
    ASSERT_LE(a.visibility[i], 1.0f) << "pixel " << i;
    sum += a.visibility[i];
  }
  EXPECT_LT(sum / static_cast<double>(a.visibility.size()), 0.99) << "the default scene has occlusion";
  for (std::size_t i = 0; i < a.color.size(); ++i) ASSERT_TRUE(a.color[i] == b.color[i]) << "colour, pixel " << i;
  for (const auto& [name, image] : a.extras)
    for (std::size_t i = 0; i < image.size(); ++i) ASSERT_EQ(image[i], b.extras.at(name)[i]) << name << ", pixel " << i;
}

// Every method estimates the obscurance integral, which with step membership can only fall as R
// grows (more of each ray's path counts as occluding): the mean over the image must fall strictly
// from R = 0.25 to 0.5 to 1 on a unit sphere resting on a plane (contact shadow grows with R).
TEST_P(AllMethods, MeanVisibilityFallsAsRadiusGrows) {
  const Fixture f = fixture("sphere-on-plane");
  double previous = 2.0;
  for (float R : {0.25f, 0.5f, 1.0f}) {
    const MethodOutput out = run(method(), f, {Membership::Step, R}, 5);
    double sum = 0;
    for (std::size_t i = 0; i < out.visibility.size(); ++i) sum += out.visibility[i];
    const double mean = sum / static_cast<double>(out.visibility.size());
    EXPECT_LT(mean, previous) << "R = " << R;
    previous = mean;
  }
}

TEST_P(AllMethods, DefaultsAreTheTablesDefaults) {
  const MethodInfo& m = method();
  const nlohmann::json defaults = m.default_params();
  const std::vector<ParamSpec>& specs = m.params().specs();
  EXPECT_EQ(defaults.size(), specs.size()) << defaults.dump();
  for (const ParamSpec& s : specs) {
    ASSERT_TRUE(defaults.contains(s.name)) << s.name;
    EXPECT_EQ(defaults.at(s.name), s.default_value) << s.name;
    EXPECT_FALSE(s.help.empty()) << s.name;
  }
}

// A valid value other than the default, of the parameter's type.
nlohmann::json other_value(const ParamSpec& s) {
  switch (s.type) {
    case ParamType::Bool: return !(*s.default_value).get<bool>();
    case ParamType::Enum: return s.enum_names.front() == (*s.default_value) ? s.enum_names.back() : s.enum_names.front();
    case ParamType::Int:
    case ParamType::OptionalInt: {
      const int lo = static_cast<int>(s.range.min_open ? s.range.min + 1 : s.range.min);
      return (*s.default_value) == lo ? nlohmann::json(static_cast<int>(s.range.max_open ? s.range.max - 1 : s.range.max)) : nlohmann::json(lo);
    }
    case ParamType::Float:
    case ParamType::OptionalFloat:
      for (double v : {0.3, 0.7, 1.5, 45.5})
        if (s.range.contains(v) && (*s.default_value) != v) return v;
  }
  return nullptr;
}

TEST_P(AllMethods, ParametersRoundTripThroughJson) {
  const MethodInfo& m = method();
  const nlohmann::json defaults = m.default_params();
  EXPECT_EQ(m.canonical_params(defaults), defaults);
  EXPECT_EQ(m.canonical_params(nlohmann::json::object()), defaults) << "absent keys take their defaults";
  for (const ParamSpec& s : m.params().specs()) {
    nlohmann::json j = defaults;
    j[s.name] = other_value(s);
    ASSERT_FALSE(j[s.name].is_null()) << s.name;
    const nlohmann::json back = m.canonical_params(j);
    EXPECT_EQ(back, j) << s.name;
    // Floats print at the precision they were given, not as the float's binary expansion.
    EXPECT_EQ(back.at(s.name).dump(), j.at(s.name).dump()) << s.name;
  }
}

// A reference depends on the scene, the camera, R, the membership and its own ray settings, never on
// a knob of the estimator it judges: changing any parameter that is not one of the method's
// quantity_params leaves the matched and the obscurance reference the same. ReferenceSpec::key is
// everything render_reference takes beyond the scene, the G-buffer, its ray settings and the seed,
// so equal keys are equal images.
TEST_P(AllMethods, NoEstimatorParameterMovesTheReference) {
  const MethodInfo& m = method();
  const nlohmann::json defaults = m.default_params();
  for (const Falloff requested : {Falloff{Membership::Step, 1.5f}, Falloff{Membership::Linear, 0.7f}}) {
    const std::string matched = matched_reference(requested, m.decode(defaults)).key();
    const std::string obscurance = choose_reference("obscurance", requested, m.decode(defaults)).key();
    for (const ParamSpec& s : m.params().specs()) {
      const bool quantity = std::find(m.quantity_params.begin(), m.quantity_params.end(), s.name) != m.quantity_params.end();
      nlohmann::json j = defaults;
      j[s.name] = other_value(s);
      const std::string moved = matched_reference(requested, m.decode(m.canonical_params(j))).key();
      if (quantity) continue;  // it chooses the quantity: its reference may differ
      EXPECT_EQ(moved, matched) << m.name << ": " << s.name << " = " << j[s.name] << " moved the reference";
      EXPECT_EQ(choose_reference("obscurance", requested, m.decode(m.canonical_params(j))).key(), obscurance) << m.name << ": " << s.name;
    }
    // Alchemy's intensity in particular, over its range, 0 included (V = 1 everywhere).
    if (m.params().find("intensity"))
      for (double sigma : {0.0, 0.1, 0.4, 1.0, 3.0}) {
        nlohmann::json j = defaults;
        j["intensity"] = sigma;
        EXPECT_EQ(matched_reference(requested, m.decode(m.canonical_params(j))).key(), matched) << "intensity " << sigma;
      }
  }
}

// Runs canonical_params on `j`, which must throw one line naming `what`.
void expect_refused(const MethodInfo& m, const nlohmann::json& j, const std::string& what, const std::string& valid = "") {
  try {
    m.canonical_params(j);
    ADD_FAILURE() << m.name << " accepted " << j.dump();
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << msg;
    EXPECT_NE(msg.find(std::string(m.name)), std::string::npos) << msg;
    EXPECT_NE(msg.find(valid), std::string::npos) << "states what is valid: " << msg;
  }
}

TEST_P(AllMethods, BadParameterValuesAreRefused) {
  const MethodInfo& m = method();
  const nlohmann::json defaults = m.default_params();
  nlohmann::json j = defaults;
  j["no_such_parameter"] = 1;
  expect_refused(m, j, "no_such_parameter");
  expect_refused(m, nlohmann::json::array(), "JSON object");
  for (const ParamSpec& s : m.params().specs()) {
    auto refused = [&](const nlohmann::json& value) {
      nlohmann::json bad = defaults;
      bad[s.name] = value;
      expect_refused(m, bad, s.name, s.valid_text());
    };
    switch (s.type) {
      case ao::ParamType::Bool: refused(3); break;
      case ao::ParamType::Enum: refused("no-such-name"); break;
      default:
        refused("text");
        // Just outside each finite bound; the message states the range.
        const bool real = s.type == ao::ParamType::Float;
        if (std::isfinite(s.range.min))
          refused(real ? nlohmann::json(s.range.min_open ? s.range.min : s.range.min - std::max(0.5, 1e-3 * std::abs(s.range.min))) : nlohmann::json(static_cast<long long>(s.range.min) - 1));
        if (std::isfinite(s.range.max))
          refused(real ? nlohmann::json(s.range.max_open ? s.range.max : s.range.max + std::max(0.5, 1e-3 * std::abs(s.range.max))) : nlohmann::json(static_cast<long long>(s.range.max) + 1));
    }
  }
}

std::vector<std::string> method_names() {
  std::vector<std::string> names;
  for (const MethodInfo& m : all_methods()) names.emplace_back(m.name);
  return names;
}

INSTANTIATE_TEST_SUITE_P(Registry, AllMethods, ::testing::ValuesIn(method_names()), [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

}  // namespace
}  // namespace ao
