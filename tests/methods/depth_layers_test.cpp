// SPDX-License-Identifier: Apache-2.0
// The deep G-buffer's second layer (Mara et al. 2016; methods/depth_layers.h): what it holds on
// shapes whose depths are known, and what the screen-space methods make of it: a plate floating
// more than R above the ground occludes none of it, which one depth layer gets wrong around the
// plate's footprint and two layers get right.
#include "ao/methods/depth_layers.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>

// The registry first: its CharacteristicKind::DepthTimesHeight would shadow characteristic.h's type of that name.
#include "ao/registry/registry.h"

#include "ao/core/error.h"
#include "ao/methods/alchemy/alchemy.h"
#include "ao/methods/characteristic.h"
#include "ao/methods/containment/containment.h"
#include "ao/methods/transfer/transfer.h"
#include "ao/methods/volumetric/volumetric.h"
#include "screen_space_fixtures.h"

namespace ao {
namespace {

// A camera on the +z axis looking at the origin, straight down -z.
Camera head_on(float distance = 10.0f) {
  Camera c;
  c.eye = {0, 0, distance};
  c.target = {0, 0, 0};
  c.vertical_fov_deg = 30.0f;
  return c;
}

Scene scene_of(std::vector<Mesh> meshes) {
  Scene s;
  s.name = "layers";
  s.meshes = std::move(meshes);
  validate_and_prepare(s);
  return s;
}

float centre_second(const test::SceneGBuffer& s) { return s.g.second_depth(test::kWidth / 2, test::kHeight / 2); }
float centre_depth(const test::SceneGBuffer& s) { return s.g.depth(test::kWidth / 2, test::kHeight / 2); }

// A closed box 2 deep seen face on: the second layer is its back face, 2 behind the front one.
TEST(DepthLayers, SecondLayerOfAClosedBoxIsItsBackFace) {
  auto s = test::scene_gbuffer(scene_of({make_box({-1, -1, -1}, {1, 1, 1})}), head_on());
  render_second_layer(*s.rays, s.g, 0.1f);
  EXPECT_NEAR(centre_depth(s), 9.0f, 1e-4f);
  EXPECT_NEAR(centre_second(s), 11.0f, 1e-4f) << "a back face: positive, at the far side's depth";
  EXPECT_EQ(s.g.second_separation, 0.1f);
  EXPECT_EQ(s.g.second_depth(0, 0), kInfinity) << "background";
  // A separation larger than the box skips its back face, and nothing lies behind it.
  render_second_layer(*s.rays, s.g, 2.5f);
  EXPECT_EQ(centre_second(s), kInfinity);
}

// A sheet in front of a box: the ray leaves the sheet's plane without a back face and enters the
// box, so the second layer is a front face (negative) at the box's depth.
TEST(DepthLayers, SecondLayerBehindASheetIsTheNextFrontFace) {
  auto s = test::scene_gbuffer(scene_of({make_quad({-2, -2, 3}, {2, -2, 3}, {2, 2, 3}, {-2, 2, 3}), make_box({-1, -1, -1}, {1, 1, 1})}), head_on());
  render_second_layer(*s.rays, s.g, 0.1f);
  EXPECT_NEAR(centre_depth(s), 7.0f, 1e-4f);
  EXPECT_NEAR(centre_second(s), -9.0f, 1e-4f);
}

TEST(DepthLayers, RejectsBadSeparationsAndMissingLayers) {
  auto s = test::scene_gbuffer(scene_of({make_box({-1, -1, -1}, {1, 1, 1})}), head_on());
  for (float bad : {0.0f, -1.0f, std::nanf(""), kInfinity}) EXPECT_THROW(render_second_layer(*s.rays, s.g, bad), InputError) << bad;
  ContainmentParams two;
  two.layers.layers = 2;
  EXPECT_THROW(containment_ao(s.g, Falloff{Membership::Step, 1.0f}, two, 1), InputError) << "no second layer in the G-buffer";
  render_second_layer(*s.rays, s.g, 0.3f);
  EXPECT_THROW(containment_ao(s.g, Falloff{Membership::Step, 1.0f}, two, 1), InputError) << "one at another separation (auto: R/4)";
  two.layers.separation = 0.3f;
  EXPECT_NO_THROW(containment_ao(s.g, Falloff{Membership::Step, 1.0f}, two, 1));
  EXPECT_THROW((ContainmentParams{.layers = {3, 0}}.validate()), InputError);
  EXPECT_THROW((VolumetricParams{.layers = {2, -1}}.validate()), InputError);
}

// Mean and minimum of V over the pixels of object `id`.
struct Stats {
  double mean = 0, min = 1;
};
Stats stats(const Image<float>& v, const GBuffer& g, std::uint32_t id) {
  Stats st;
  int n = 0;
  for (std::size_t i = 0; i < v.size(); ++i)
    if (g.object_id[i] == id) st.mean += v[i], st.min = std::min(st.min, static_cast<double>(v[i])), ++n;
  st.mean /= n;
  return st;
}

// A plate floating 2 R above the ground, seen from above: no ground point has anything within R
// (V = 1 for step obscurance at R). One layer takes everything below the plate for solid and
// draws a halo around its footprint (AT 4.3's silhouette elimination is the paper's heuristic for
// it, off here); two layers know the plate ends at its bottom face.
TEST(DepthLayers, TheGroundUnderAFloatingPlateIsFreeWithTwoLayers) {
  auto s = test::scene_gbuffer(scene_of({make_quad({-6, -6, 0}, {6, -6, 0}, {6, 6, 0}, {-6, 6, 0}), make_box({-1, -1, 2}, {1, 1, 2.3f})}),
                               head_on(12.0f));
  const float R = 1.0f;
  render_second_layer(*s.rays, s.g, kAutoSeparation * R);
  const Falloff f{Membership::Step, R};
  ContainmentParams c1, c2;
  c1.silhouette_elimination = c2.silhouette_elimination = false;  // the layers alone
  c2.layers.layers = 2;
  VolumetricParams v1, v2;
  v1.silhouette_elimination = v2.silhouette_elimination = false;
  v2.layers.layers = 2;
  TransferParams t1, t2;
  t1.silhouette_elimination = t2.silhouette_elimination = false;
  t2.layers.layers = 2;
  const Stats sc1 = stats(containment_ao(s.g, f, c1, 3), s.g, 1), sc2 = stats(containment_ao(s.g, f, c2, 3), s.g, 1);
  const Stats sv1 = stats(volumetric_ao(s.g, R, v1, 3), s.g, 1), sv2 = stats(volumetric_ao(s.g, R, v2, 3), s.g, 1);
  const Stats st1 = stats(transfer_ao(s.g, f, t1, 3).obscurance, s.g, 1), st2 = stats(transfer_ao(s.g, f, t2, 3).obscurance, s.g, 1);
  std::printf("ground: mean (min) V, one layer / two: containment %.4f (%.3f) / %.4f (%.3f), volumetric %.4f (%.3f) / %.4f (%.3f), "
              "transfer O %.4f (%.3f) / %.4f (%.3f)\n",
              sc1.mean, sc1.min, sc2.mean, sc2.min, sv1.mean, sv1.min, sv2.mean, sv2.min, st1.mean, st1.min, st2.mean, st2.min);
  EXPECT_LT(sc1.min, 0.8) << "one layer: a halo around the plate's footprint";
  EXPECT_LT(sv1.min, 0.8);
  EXPECT_LT(st1.min, 0.8);
  EXPECT_EQ(sc2.min, 1.0) << "two layers: the ground is open everywhere";
  EXPECT_EQ(sv2.min, 1.0);
  EXPECT_EQ(st2.min, 1.0);
}

// Alchemy with two layers takes the larger term of each tap's two points (eq. 10's sum only
// grows), so before the filter no pixel is brighter than with one; on the default scene, where
// the backs of the sphere, box and torus hide near the ground, some pixels are darker.
TEST(DepthLayers, AlchemyTapsOnlyGainOccluders) {
  auto s = test::builtin_gbuffer("default");
  const float R = 1.5f;
  AlchemyParams one, two;
  one.filter = two.filter = false;
  two.layers.layers = 2;
  render_second_layer(*s.rays, s.g, effective_separation(two.layers, R));
  const Image<float> a = render_alchemy(s.g, one, R, 2).visibility, b = render_alchemy(s.g, two, R, 2).visibility;
  int darker = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_LE(b[i], a[i]) << "pixel " << i;
    darker += b[i] < a[i] ? 1 : 0;
  }
  EXPECT_GT(darker, 100);
}

// Through the registry (what ao render, compare, view and Python run) a method asked for two
// layers traces the second one from the scene for its run: the same image as the library call on
// a G-buffer that carries it. Without a scene (a G-buffer file) it is refused with a clear error.
TEST(DepthLayers, TheRegistryTracesTheLayerFromTheSceneOrRefuses) {
  auto s = test::builtin_gbuffer("default");
  const Falloff falloff{Membership::Step, 1.5f};
  for (const char* name : {"containment", "volumetric", "transfer", "alchemy"}) {
    const MethodInfo& m = find_method(name);
    const nlohmann::json params = m.canonical_params({{"layers", 2}});
    const Image<float> via_registry = run_method(MethodInput{s.g, s.rays.get(), falloff, 7}, m.decode(params)).visibility;
    GBuffer g = s.g;
    render_second_layer(*s.rays, g, effective_separation(DepthLayers{2, 0}, falloff.radius));
    const Image<float> direct = run_method(MethodInput{g, nullptr, falloff, 7}, m.decode(params)).visibility;
    ASSERT_EQ(via_registry.size(), direct.size());
    for (std::size_t i = 0; i < direct.size(); ++i) ASSERT_EQ(via_registry[i], direct[i]) << name << ", pixel " << i;
    EXPECT_THROW(run_method(MethodInput{s.g, nullptr, falloff, 7}, m.decode(params)), InputError) << name << ": no scene, no second layer";
  }
}

// Two layers are a property of the depth buffer: an analytic characteristic function has its own
// solid, and asking it for two layers is refused.
TEST(DepthLayers, AnalyticCharacteristicsHaveOneLayer) {
  const GBuffer g = test::one_pixel({0, 0, -5}, {0, 0, 1});
  ImplicitCharacteristic ch;
  ch.add(ImplicitPrimitive::half_space({0, 0, 1}, {0, 0, -5}));
  ContainmentParams p;
  p.layers.layers = 2;
  EXPECT_THROW(containment_ao(g, ch, Falloff{Membership::Step, 1.0f}, p, 1), InputError);
}

}  // namespace
}  // namespace ao
