// SPDX-License-Identifier: Apache-2.0
// The registry's characteristic-function choice for the screen-space methods (registry.h,
// kCharacteristicParam): the paper's other characteristic functions (VAO fig. 2a implicit, 2b height
// field, fig. 12 depth x height field) on the built-in scenes that describe them, against known
// answers and the ray-traced reference, and the bad inputs. The tests print what they measure:
//   ./build/tests/ao_tests --gtest_filter='Registry.*'
#include "ao/registry/registry.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <string>
#include <vector>

#include "ao/core/error.h"
#include "ao/methods/containment/containment.h"
#include "ao/methods/transfer/transfer.h"
#include "ao/methods/volumetric/volumetric.h"
#include "methods/screen_space_fixtures.h"

namespace ao {
namespace {

constexpr const char* kScreenSpace[] = {"containment", "volumetric", "transfer"};

// Runs `method` on the scene's G-buffer through the registry with its defaults and `overrides`.
MethodOutput run(const test::SceneGBuffer& s, const char* method, const Falloff& f, nlohmann::json overrides,
                 const AnalyticSurfaces* surfaces, std::uint32_t seed = 1) {
  const MethodInfo& m = find_method(method);
  nlohmann::json p = m.default_params();
  for (const auto& [k, v] : overrides.items()) p[k] = v;
  return run_method(MethodInput{s.g, s.rays.get(), f, seed, {}, surfaces}, m.decode(p));
}
MethodOutput run(const test::SceneGBuffer& s, const char* method, const Falloff& f, const char* characteristic) {
  return run(s, method, f, {{"characteristic", characteristic}}, &s.scene.analytic);
}

// The image each method's reference is compared with: V, or for transfer its obscurance O (W is
// brighter than the obscurance reference by design; O is what approximates it).
const Image<float>& compared(const MethodOutput& out, const char* method) {
  return std::string(method) == "transfer" ? out.extras.at("obscurance") : out.visibility;
}

// The obscurance each method approximates (`ao compare --reference obscurance`).
Falloff reference_falloff(const char* method, const Falloff& requested) {
  const MethodInfo& m = find_method(method);
  return obscurance_falloff(requested, m.decode(m.default_params()));
}

double covered_mean(const Image<float>& v, const GBuffer& g) {
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < v.size(); ++i)
    if (g.covered(i)) sum += v[i], ++n;
  return n ? sum / static_cast<double>(n) : 1.0;
}

// GTAO's multi-bounce fit estimates the light after interreflections with a neighbourhood of the
// receiver's albedo (Jimenez et al. 2016, sec. 5), which the ray-traced ambient transfer W with the
// receiver's albedo computes; without it GTAO
// estimates the cosine-weighted visibility within R, step obscurance, whatever membership is asked.
TEST(Registry, GtaoWithMultiBounceIsJudgedAgainstAmbientTransfer) {
  const MethodInfo& m = find_method("gtao");
  nlohmann::json p = m.default_params();
  const ReferenceSpec plain = matched_reference({Membership::Linear, 1.5f}, m.decode(p));
  EXPECT_EQ(plain.kind, ReferenceKind::Obscurance);
  EXPECT_EQ(plain.falloff.membership, Membership::Step);
  EXPECT_EQ(plain.falloff.radius, 1.5f);
  p["multi_bounce"] = true;
  const ReferenceSpec bounced = matched_reference({Membership::Linear, 1.5f}, m.decode(m.canonical_params(p)));
  EXPECT_EQ(bounced.kind, ReferenceKind::Transfer);
  EXPECT_EQ(bounced.falloff.membership, Membership::Step);
  EXPECT_EQ(bounced.falloff.radius, 1.5f);
  EXPECT_EQ(bounced.albedo_scale, 1.0f);
  EXPECT_EQ(bounced.albedo, TransferAlbedo::Receiver);
  EXPECT_EQ(choose_reference("transfer", {Membership::Linear, 1.5f}, m.decode(m.canonical_params(p))).albedo, TransferAlbedo::Occluders);
}

TEST(Registry, ScreenSpaceMethodsOfferTheFourCharacteristicFunctions) {
  ASSERT_EQ(characteristic_names().size(), 4u);
  EXPECT_EQ(characteristic_names()[0], "depth");
  for (const char* method : kScreenSpace) EXPECT_EQ(find_method(method).default_params().at("characteristic"), "depth") << method;
  for (const char* method : {"raytraced", "cone", "alchemy"}) EXPECT_FALSE(find_method(method).default_params().contains("characteristic")) << method;
}

// The default and "depth" run exactly the library's depth-buffer overloads.
TEST(Registry, DepthCharacteristicIsTheScreenSpaceMethodBitForBit) {
  const auto s = test::builtin_gbuffer("default");
  const Falloff f{Membership::Linear, 1.0f};
  const Image<float> c = containment_ao(s.g, f, {}, 7);
  const Image<float> v = volumetric_ao(s.g, f.radius, {}, 7);
  const TransferImage t = transfer_ao(s.g, f, {}, 7);
  for (const AnalyticSurfaces* surfaces : {static_cast<const AnalyticSurfaces*>(nullptr), &s.scene.analytic}) {
    const MethodOutput rc = run(s, "containment", f, {{"characteristic", "depth"}}, surfaces, 7);
    const MethodOutput rv = run(s, "volumetric", f, nlohmann::json::object(), surfaces, 7);
    const MethodOutput rt = run(s, "transfer", f, {{"characteristic", "depth"}}, surfaces, 7);
    for (std::size_t i = 0; i < c.size(); ++i) {
      ASSERT_EQ(rc.visibility[i], c[i]) << "pixel " << i;
      ASSERT_EQ(rv.visibility[i], v[i]) << "pixel " << i;
      ASSERT_EQ(rt.visibility[i], t.luminance[i]) << "pixel " << i;
      ASSERT_EQ(rt.extras.at("obscurance")[i], t.obscurance[i]) << "pixel " << i;
    }
    EXPECT_FALSE(rc.stats->contains("characteristic"));
  }
}

// A MethodCache kept across calls (what ao view does frame after frame) changes no pixel: cone
// through its kept voxel grid, transfer through its kept scratch images, for two calls each, the
// second with another seed, and another method's entry beside them; then another scene.
TEST(Registry, MethodCacheGivesTheSameImagesAsNoCache) {
  const auto s = test::builtin_gbuffer("default");
  const Falloff f{Membership::Step, 1.0f};
  MethodCache cache;
  for (const char* method : {"cone", "transfer", "cone"})
    for (std::uint32_t seed : {3u, 8u}) {
      const MethodInfo& m = find_method(method);
      const nlohmann::json p = m.default_params();
      const MethodOutput plain = run_method(MethodInput{s.g, s.rays.get(), f, seed, {}, &s.scene.analytic}, m.decode(p));
      const MethodOutput cached = run_method(MethodInput{s.g, s.rays.get(), f, seed, {}, &s.scene.analytic, &cache}, m.decode(p));
      ASSERT_EQ(plain.visibility.size(), cached.visibility.size());
      for (std::size_t i = 0; i < plain.visibility.size(); ++i) ASSERT_EQ(plain.visibility[i], cached.visibility[i]) << method << " pixel " << i;
      for (std::size_t i = 0; i < plain.color.size(); ++i) ASSERT_EQ(plain.color[i], cached.color[i]) << method << " pixel " << i;
    }
  // The same cache handed another scene: cone voxelizes that scene, not the kept grid.
  const auto other = test::builtin_gbuffer("sphere-on-plane");
  const MethodInfo& cone = find_method("cone");
  const MethodOutput plain = run_method(MethodInput{other.g, other.rays.get(), f, 3, {}, &other.scene.analytic}, cone.decode(cone.default_params()));
  const MethodOutput cached = run_method(MethodInput{other.g, other.rays.get(), f, 3, {}, &other.scene.analytic, &cache}, cone.decode(cone.default_params()));
  for (std::size_t i = 0; i < plain.visibility.size(); ++i) ASSERT_EQ(plain.visibility[i], cached.visibility[i]) << "pixel " << i;
}

// An open plane as the half-space y >= 0: every sample point of the hemisphere (containment,
// transfer) and every pipe of the tangent sphere (volumetric) lies in it, and the Taylor distance
// of a plane is exact, so V = 1 at every pixel, without the depth buffer's perspective error.
TEST(Registry, ImplicitOpenPlaneIsFullyVisible) {
  const auto s = test::builtin_gbuffer("plane");
  for (const char* method : kScreenSpace) {
    const MethodOutput out = run(s, method, {Membership::Linear, 2.0f}, "implicit");
    EXPECT_EQ(out.stats->at("characteristic"), "implicit");
    EXPECT_EQ(out.stats->at("silhouette_elimination"), "off");
    for (std::size_t i = 0; i < out.visibility.size(); ++i) {
      ASSERT_GE(out.visibility[i], 1.0f - 1e-5f) << method << ", pixel " << i;  // float rounding of V = sum / n
      ASSERT_GE(compared(out, method)[i], 1.0f - 1e-5f) << method << ", pixel " << i;
    }
  }
}

// The wedge (floor y >= 0 and wall z >= 0) as two half-spaces, R = 0.5, against the ray-traced
// reference of each method's integral (1024 rays: standard error ~0.001, negligible). The implicit
// function knows the solid behind the wall and the floor, which the depth buffer guesses from what
// is visible. Tolerances: containment and transfer (step membership: a test point counts wherever on the ray it lies) are left
// with their sampling noise, 12 points per pixel averaged over the 4x4 filter, sqrt(V(1-V)/192) <=
// 0.036 per pixel; measured RMSE 0.032 (depth buffer: 0.047 and 0.037). Volumetric's error is the
// method's own (the free fraction of the tangent sphere is not exactly the cubic obscurance: a ray
// at angle theta leaves the sphere after R cos theta, not R), measured 0.051 with either function,
// so there the implicit function must only do no worse than the depth buffer.
TEST(Registry, ImplicitWedgeAgreesWithTheReference) {
  const auto s = test::builtin_gbuffer("wedge");
  const Falloff f{Membership::Step, 0.5f};
  for (const char* method : kScreenSpace) {
    const Falloff rf = reference_falloff(method, f);
    const RaytracedImage ref = render_raytraced(*s.rays, s.g, rf, {.samples = 1024}, 99);
    const double e_implicit = test::rmse_against(compared(run(s, method, f, "implicit"), method), ref.visibility, s.g);
    const double e_depth = test::rmse_against(compared(run(s, method, f, "depth"), method), ref.visibility, s.g);
    std::printf("wedge, R = 0.5, %s: RMSE implicit %.4f, depth %.4f (reference mean standard error %.4f)\n", method, e_implicit, e_depth,
                ref.mean_std_error);
    if (std::string(method) == "volumetric") {
      EXPECT_LT(e_implicit, e_depth + 0.002) << method;
      EXPECT_LT(e_implicit, 0.06) << method;
    } else {
      EXPECT_LT(e_implicit, 0.04) << method;
      EXPECT_LT(e_implicit, e_depth) << method;
    }
  }
}

// Sphere-on-plane: the plane and the sphere's exterior. The contact shadow under the sphere is where
// the depth buffer is worst (the sphere hides the floor behind it). Measured (R = 0.5, 160x120):
// RMSE implicit against depth 0.015 / 0.060 (containment), 0.016 / 0.019 (volumetric), 0.015 /
// 0.050 (transfer's obscurance).
TEST(Registry, ImplicitSphereOnPlaneIsCloserToTheReferenceThanTheDepthBuffer) {
  const auto s = test::builtin_gbuffer("sphere-on-plane");
  const Falloff f{Membership::Step, 0.5f};
  for (const char* method : kScreenSpace) {
    const RaytracedImage ref = render_raytraced(*s.rays, s.g, reference_falloff(method, f), {.samples = 1024}, 99);
    const double e_implicit = test::rmse_against(compared(run(s, method, f, "implicit"), method), ref.visibility, s.g);
    const double e_depth = test::rmse_against(compared(run(s, method, f, "depth"), method), ref.visibility, s.g);
    std::printf("sphere-on-plane, R = 0.5, %s: RMSE implicit %.4f, depth %.4f\n", method, e_implicit, e_depth);
    EXPECT_LT(e_implicit, e_depth) << method;
  }
}


// VAO fig. 12 on the displaced floor, whose mesh is the height field itself: the depth buffer
// misses the solid behind the domes (it sees only their fronts, and silhouette elimination frees
// points behind a dome seen at a grazing angle), the height field alone misses the sphere and the
// box, their product has both. Containment's product is at least as dark as the depth buffer at
// every pixel (I_z * I_h <= I_z for every test point; the wrapped depth factor eliminates exactly
// what the kernel would), and so is transfer's obscurance.
TEST(Registry, DepthTimesHeightFieldOnDisplacedFloorIsDarkerAndCloserToTheReference) {
  const auto s = test::builtin_gbuffer("displaced");
  const Falloff f{Membership::Step, 1.0f};
  for (const char* method : kScreenSpace) {
    const Falloff rf = reference_falloff(method, f);
    const RaytracedImage ref = render_raytraced(*s.rays, s.g, rf, {.samples = 1024}, 99);
    const MethodOutput depth = run(s, method, f, "depth"), hf = run(s, method, f, "height-field"), both = run(s, method, f, "depth*height-field");
    const double e_depth = test::rmse_against(compared(depth, method), ref.visibility, s.g);
    const double e_hf = test::rmse_against(compared(hf, method), ref.visibility, s.g);
    const double e_both = test::rmse_against(compared(both, method), ref.visibility, s.g);
    const double m_depth = covered_mean(compared(depth, method), s.g), m_both = covered_mean(compared(both, method), s.g);
    const double m_ref = covered_mean(ref.visibility, s.g);
    std::printf("displaced, R = 1, %s: RMSE depth %.4f, height-field %.4f, depth*height-field %.4f; mean V %.4f, %.4f, %.4f, reference %.4f\n",
                method, e_depth, e_hf, e_both, m_depth, covered_mean(compared(hf, method), s.g), m_both, m_ref);
    EXPECT_EQ(both.stats->at("silhouette_elimination"), "depth-buffer factor only");
    EXPECT_LT(m_both, m_depth) << method;
    EXPECT_LT(e_both, e_depth) << method;
    EXPECT_LT(e_both, e_hf) << method;
    if (std::string(method) != "volumetric") {
      const Image<float>& a = compared(depth, method);
      const Image<float>& b = compared(both, method);
      for (std::size_t i = 0; i < a.size(); ++i) ASSERT_LE(b[i], a[i] + 1e-6f) << method << ", pixel " << i;
    }
  }
}

// Bad input: one line naming the parameter or what the scene lacks and where to find it.
template <class Fn>
void expect_input_error(Fn&& fn, const std::vector<std::string>& needles) {
  try {
    fn();
    ADD_FAILURE() << "no exception";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    for (const std::string& n : needles) EXPECT_NE(what.find(n), std::string::npos) << "expected '" << n << "' in: " << what;
  }
}

TEST(Registry, UnknownCharacteristicNamesTheChoices) {
  const auto s = test::builtin_gbuffer("plane");
  const Falloff f{Membership::Step, 1.0f};
  for (const char* method : kScreenSpace) {
    expect_input_error([&] { run(s, method, f, "heightfield"); }, {method, "characteristic", "depth*height-field", "heightfield"});
    expect_input_error([&] { run(s, method, f, {{"characteristic", 3}}, &s.scene.analytic); }, {method, "characteristic"});
    // The other keys are still checked by the method's own from_json.
    expect_input_error([&] { run(s, method, f, {{"characteristic", "implicit"}, {"smaples", 4}}, &s.scene.analytic); }, {"smaples"});
  }
}

TEST(Registry, AnalyticCharacteristicNeedsASceneThatHasOne) {
  const auto wedge = test::builtin_gbuffer("wedge");
  const auto displaced = test::builtin_gbuffer("displaced");
  const Falloff f{Membership::Step, 1.0f};
  for (const char* method : kScreenSpace) {
    expect_input_error([&] { run(wedge, method, f, "height-field"); }, {method, "'wedge'", "displaced"});
    expect_input_error([&] { run(wedge, method, f, "depth*height-field"); }, {"'wedge'", "displaced"});
    expect_input_error([&] { run(displaced, method, f, "implicit"); }, {"'displaced'", "plane, wedge, sphere-on-plane"});
    // From --gbuffer-in: no description at all.
    expect_input_error([&] { run(wedge, method, f, {{"characteristic", "implicit"}}, nullptr); }, {"--gbuffer-in", "plane, wedge, sphere-on-plane"});
    expect_input_error([&] { run(displaced, method, f, {{"characteristic", "height-field"}}, nullptr); }, {"--gbuffer-in", "displaced"});
  }
}

// More primitives than ImplicitCharacteristic holds (a scene built by hand) is an input error too.
TEST(Registry, ImplicitSurfaceWithTooManyPrimitivesIsAnInputError) {
  const auto s = test::builtin_gbuffer("plane");
  AnalyticSurfaces surfaces;
  surfaces.implicit.emplace();
  for (int k = 0; k < 5; ++k) surfaces.implicit->primitives.push_back(ImplicitSurfacePrimitive::half_space({0, -1.0f * k, 0}, {0, 1, 0}));
  expect_input_error([&] { run(s, "containment", {Membership::Step, 1.0f}, {{"characteristic", "implicit"}}, &surfaces); }, {"5 primitives", "1 to 4"});
}

// A row's decode makes its own alternative of MethodParams (the rows are in the variant's order),
// and params_json gives back the table's complete JSON: what --json echoes is what was decoded.
TEST(Registry, DecodeGivesTheRowsOwnStruct) {
  for (const MethodInfo& m : all_methods()) {
    const MethodParams p = m.decode(m.default_params());
    EXPECT_EQ(&method_of(p), &m) << m.name;
    EXPECT_EQ(params_json(p), m.default_params()) << m.name;
    const MethodParams overridden = m.decode(nlohmann::json::object());
    EXPECT_EQ(params_json(overridden), m.default_params()) << m.name << ": no overrides decode to the defaults";
  }
  EXPECT_THROW(find_method("gtao").decode({{"slices", 0}}), InputError);
  EXPECT_THROW(find_method("gtao").decode({{"no_such_parameter", 1}}), InputError);
}

}  // namespace
}  // namespace ao
