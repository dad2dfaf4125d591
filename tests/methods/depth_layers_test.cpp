// SPDX-License-Identifier: Apache-2.0
// The deep G-buffer's second layer (Mara et al. 2016; methods/depth_layers.h): what it holds on
// shapes whose depths are known, and what the screen-space methods make of it: a sheet floating
// more than R above the ground occludes none of it, which one depth layer gets wrong around the
// sheet's footprint and two layers get right; on the open-mesh suite two layers keep containment
// and volumetric near their error on closed meshes. Without a second layer, one layer's sheets of
// a thickness free the space behind them likewise where nothing else lies behind.
#include "ao/methods/depth_layers.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string_view>
#include <utility>

// The registry first: its CharacteristicKind::DepthTimesHeight would shadow characteristic.h's type of that name.
#include "ao/registry/registry.h"

#include "ao/core/error.h"
#include "ao/eval/metrics.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/reference/raytraced.h"
#include "ao/reference/tangent_sphere.h"
#include "ao/methods/alchemy/alchemy.h"
#include "ao/methods/characteristic.h"
#include "ao/methods/containment/containment.h"
#include "ao/methods/transfer/transfer.h"
#include "ao/methods/volumetric/volumetric.h"
#include "screen_space_fixtures.h"
#include "support/open_sheets.h"

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
  EXPECT_TRUE(second_layer_exit(centre_second(s))) << "where the ray leaves a closed solid";
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

// Where the second layer is a closed solid's exit, and where a back face says nothing of the
// kind: a closed box whose fronts face in is left through a front face (still its exit); a sheet's
// back (a quad turned away from the eye) and a room's wall behind a sheet (the eye inside a closed
// box) are back faces only.
TEST(DepthLayers, SecondLayerMarksWhereTheRayLeavesAClosedSolid) {
  const Mesh inward = make_box({-1, -1, -1}, {1, 1, 1}, {0.8f, 0.8f, 0.8f}, 0.0f, true);
  auto box = test::scene_gbuffer(scene_of({inward}), head_on());
  render_second_layer(*box.rays, box.g, 0.1f);
  EXPECT_NEAR(centre_second(box), 11.0f, 1e-4f);
  EXPECT_TRUE(second_layer_exit(centre_second(box)));

  const Mesh front = make_quad({-2, -2, 3}, {2, -2, 3}, {2, 2, 3}, {-2, 2, 3}), turned = make_quad({-2, -2, 1}, {-2, 2, 1}, {2, 2, 1}, {2, -2, 1});
  auto sheets = test::scene_gbuffer(scene_of({front, turned}), head_on());
  render_second_layer(*sheets.rays, sheets.g, 0.1f);
  EXPECT_NEAR(centre_second(sheets), -9.0f, 1e-4f) << "a flat sheet is met from its front, however it is wound";

  auto room = test::scene_gbuffer(scene_of({front, make_box({-20, -20, -20}, {20, 20, 20})}), head_on());
  render_second_layer(*room.rays, room.g, 0.1f);
  EXPECT_NEAR(centre_second(room), -30.0f, 1e-3f) << "the room's far wall, from inside: where its solid begins";
  // Where the room's wall itself is seen (beside the sheet), its solid is everything outside it: no
  // end, whatever the ray would meet past the wall.
  ASSERT_EQ(room.g.object_id(2, 2), 2u) << "the room is seen there";
  EXPECT_EQ(room.g.second_depth(2, 2), kSecondLayerSolidOnward);
  EXPECT_GT(kSecondLayerSolidOnward, 1e38f);
  EXPECT_FALSE(second_layer_exit(kSecondLayerSolidOnward)) << "a back face, not an exit";
}

// A file's winding of an open mesh is arbitrary (scans, exports): the second layer reads the gutter
// (a half pipe, its hollow seen through its top and behind its near wall) and the ground under it
// the same when both are turned over.
TEST(DepthLayers, AnOpenMeshsWindingDoesNotChangeTheSecondLayer) {
  const Mesh gutter = test::make_gutter(), ground = test::ground_under(gutter);
  const Camera camera = frame_bounds(gutter.bounds(), {1.0f, 0.8f, 1.3f}, 40.0f, 160, 90);
  Image<float> layers[2];
  for (int turned = 0; turned < 2; ++turned) {
    const Scene s = turned ? scene_of({test::turned_over(gutter), test::turned_over(ground)}) : scene_of({gutter, ground});
    const RayScene rs(s);
    GBuffer g = render_gbuffer(rs, camera);
    render_second_layer(rs, g, 0.05f);
    layers[turned] = g.second_depth;
  }
  int backs = 0, fronts = 0;
  for (int y = 0; y < 90; ++y)
    for (int x = 0; x < 160; ++x) {
      // The same side and depth; Embree's t of a triangle listed the other way round may differ in
      // its last bits.
      const float s2 = layers[0](x, y), turned = layers[1](x, y);
      ASSERT_EQ(s2 < 0, turned < 0) << x << ", " << y;
      ASSERT_EQ(second_layer_exit(s2), second_layer_exit(turned)) << x << ", " << y;
      if (std::isfinite(s2)) ASSERT_NEAR(s2, turned, 1e-5f * std::abs(s2)) << x << ", " << y;
      else ASSERT_EQ(s2, turned) << x << ", " << y;
      backs += s2 > 0 && s2 < kInfinity, fronts += s2 < 0;
    }
  EXPECT_GT(backs, 100) << "the hollow's far wall met from the gutter's inside";
  EXPECT_GT(fronts, 100) << "the ground, and the far wall met from outside";
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
  // One layer's sheets: a thickness >= 0, and not with two layers (the second layer says what lies behind).
  EXPECT_THROW((TransferParams{.layers = {1, 0, -0.5f}}.validate()), InputError);
  EXPECT_THROW((ContainmentParams{.layers = {1, 0, std::nanf("")}}.validate()), InputError);
  EXPECT_THROW((VolumetricParams{.layers = {2, 0, 0.5f}}.validate()), InputError);
  EXPECT_NO_THROW((VolumetricParams{.layers = {1, 0, 0.5f}}.validate()));
  ContainmentParams both = two;
  both.layers.thickness = 0.3f;
  EXPECT_THROW(containment_ao(s.g, Falloff{Membership::Step, 1.0f}, both, 1), InputError);
  // The GPU shaders read one layer, with its sheets of a thickness (tests/gpu/methods_test.cpp).
  EXPECT_THROW(check_gpu(ContainmentParams{.layers = {2, 0}}), InputError);
  EXPECT_NO_THROW(check_gpu(ContainmentParams{.layers = {1, 0, 0.3f}}));
  EXPECT_NO_THROW(check_gpu(VolumetricParams{.layers = {1, 0, 0.3f}}));
  EXPECT_NO_THROW(check_gpu(TransferParams{.layers = {1, 0, 0.3f}}));
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

// The ground's V around a floating occluder (object 1 is the ground) with one layer and with
// `second`: two layers, or one layer's sheets of a thickness.
void check_floating_occluder(const test::SceneGBuffer& s, const DepthLayers& second) {
  const float R = 1.0f;
  const Falloff f{Membership::Step, R};
  ContainmentParams c1, c2;
  c1.silhouette_elimination = c2.silhouette_elimination = false;  // the layers alone
  c2.layers = second;
  VolumetricParams v1, v2;
  v1.silhouette_elimination = v2.silhouette_elimination = false;
  v2.layers = second;
  TransferParams t1, t2;
  t1.silhouette_elimination = t2.silhouette_elimination = false;
  t2.layers = second;
  const Stats sc1 = stats(containment_ao(s.g, f, c1, 3), s.g, 1), sc2 = stats(containment_ao(s.g, f, c2, 3), s.g, 1);
  const Stats sv1 = stats(volumetric_ao(s.g, R, v1, 3), s.g, 1), sv2 = stats(volumetric_ao(s.g, R, v2, 3), s.g, 1);
  const Stats st1 = stats(transfer_ao(s.g, f, t1, 3).obscurance, s.g, 1), st2 = stats(transfer_ao(s.g, f, t2, 3).obscurance, s.g, 1);
  std::printf("ground: mean (min) V, one layer / two: containment %.4f (%.3f) / %.4f (%.3f), volumetric %.4f (%.3f) / %.4f (%.3f), "
              "transfer O %.4f (%.3f) / %.4f (%.3f)\n",
              sc1.mean, sc1.min, sc2.mean, sc2.min, sv1.mean, sv1.min, sv2.mean, sv2.min, st1.mean, st1.min, st2.mean, st2.min);
  EXPECT_LT(sc1.min, 0.8) << "one layer: a halo around the occluder's footprint";
  EXPECT_LT(sv1.min, 0.8);
  EXPECT_LT(st1.min, 0.8);
  EXPECT_EQ(sc2.min, 1.0) << "the second layer: the ground is open everywhere";
  EXPECT_EQ(sv2.min, 1.0);
  EXPECT_EQ(st2.min, 1.0);
}

// A sheet floating 2 R above the ground, seen from above: no ground point has anything within R
// (V = 1 for step obscurance at R). One layer takes everything below the sheet for solid and
// draws a halo around its footprint (AT 4.3's silhouette elimination is the paper's heuristic for
// it, off here). With two layers the ground is the front face behind the sheet, so the space
// between them is solid only for a receiver the sheet hides it from: one on the camera's side of
// the sheet's plane whose segment meets that plane on the sheet. The ground lies below the plane.
// A closed plate thinner than the separation (R/4) is a sheet to the second layer; a thicker one
// is a closed solid, whose far side is taken for solid (docs/methods/depth-layers.md measures why).
TEST(DepthLayers, TheGroundUnderAFloatingSheetIsFreeWithTwoLayers) {
  for (const auto& [what, floating] : {std::pair{"sheet", make_quad({-1, -1, 2}, {1, -1, 2}, {1, 1, 2}, {-1, 1, 2})},
                                       std::pair{"plate 0.2 R thick", make_box({-1, -1, 2}, {1, 1, 2.2f})}}) {
    SCOPED_TRACE(what);
    auto s = test::scene_gbuffer(scene_of({make_quad({-6, -6, 0}, {6, -6, 0}, {6, 6, 0}, {-6, 6, 0}), floating}), head_on(12.0f));
    render_second_layer(*s.rays, s.g, kAutoSeparation);  // at R = 1
    check_floating_occluder(s, DepthLayers{2, 0});
  }
}

// The same with one layer and sheets R/4 thick (depth_layers.h: what one layer takes when no second
// layer can be traced): the sheet and the plate 0.2 R thick end within R/4 of their top, and the
// ground below them lies on the far side of their plane, so it is open everywhere as with two
// layers, though the G-buffer holds no second layer.
TEST(DepthLayers, TheGroundUnderAFloatingSheetIsFreeWithOneLayersSheets) {
  for (const auto& [what, floating] : {std::pair{"sheet", make_quad({-1, -1, 2}, {1, -1, 2}, {1, 1, 2}, {-1, 1, 2})},
                                       std::pair{"plate 0.2 R thick", make_box({-1, -1, 2}, {1, 1, 2.2f})}}) {
    SCOPED_TRACE(what);
    auto s = test::scene_gbuffer(scene_of({make_quad({-6, -6, 0}, {6, -6, 0}, {6, 6, 0}, {-6, 6, 0}), floating}), head_on(12.0f));
    ASSERT_TRUE(s.g.second_depth.empty()) << "one layer: nothing traced behind the visible surface";
    check_floating_occluder(s, DepthLayers{1, 0, 0.25f});
  }
}

// A wall (an open quad, 0.5 R high) standing on the ground, seen from the front and above: a point
// on the ground before it is hidden from what lies behind the wall, as the camera is. The ground
// is the front face behind the wall, so the wall is a sheet to the second layer; the space between
// them is solid for the ground before it (on the camera's side of its plane, the segment meeting
// the plane on the wall) and open for the ground beyond its top edge. Two layers stay as close to
// the reference as one there (measured: containment 0.0333 against one layer's 0.0362, volumetric
// 0.0338 against 0.0340; taking that space for open, as before the sheet test, brightened the
// ground before the wall: 0.0409 and 0.0359).
TEST(DepthLayers, TheGroundBeforeAWallIsHiddenFromWhatLiesBehindIt) {
  Camera view;
  view.eye = {1.0f, 2.5f, 4.0f};
  view.target = {0, 0.2f, 0};
  view.vertical_fov_deg = 45.0f;
  const Mesh ground = make_quad({-6, 0, 6}, {6, 0, 6}, {6, 0, -6}, {-6, 0, -6}), wall = make_quad({-2, 0, 0}, {2, 0, 0}, {2, 0.5f, 0}, {-2, 0.5f, 0});
  auto s = test::scene_gbuffer(scene_of({ground, wall}), view);
  const float R = 1.0f;
  render_second_layer(*s.rays, s.g, kAutoSeparation * R);
  const Falloff f{Membership::Step, R};
  const Image<float> ref = render_raytraced(*s.rays, s.g, f, {.samples = 512}, 5).visibility;
  Image<std::uint8_t> on_ground(s.g.width(), s.g.height(), 0);
  for (std::size_t i = 0; i < on_ground.size(); ++i) on_ground[i] = s.g.object_id[i] == 1 ? 1 : 0;
  ContainmentParams c1, c2;
  c2.layers.layers = 2;
  VolumetricParams v1, v2;
  v2.layers.layers = 2;
  const Image<float> sphere = render_tangent_sphere(*s.rays, s.g, R, {.samples = 512}, 5).visibility;
  const double ec1 = compare_images(containment_ao(s.g, f, c1, 3), ref, on_ground).rmse;
  const double ec2 = compare_images(containment_ao(s.g, f, c2, 3), ref, on_ground).rmse;
  const double ev1 = compare_images(volumetric_ao(s.g, R, v1, 3), sphere, on_ground).rmse;
  const double ev2 = compare_images(volumetric_ao(s.g, R, v2, 3), sphere, on_ground).rmse;
  std::printf("ground before a wall, RMSE one layer / two: containment %.4f / %.4f, volumetric %.4f / %.4f\n", ec1, ec2, ev1, ev2);
  EXPECT_LE(ec2, 1.1 * ec1);
  EXPECT_LE(ev2, 1.1 * ev1);
}

// A sphere resting on the ground, seen from the front and above, AT 4.3's elimination on (the
// default): the ground under its bulge beside the contact is dark in the references, but the
// sphere's surface seen at the test points' pixels lies more than R in front of them, so one layer
// eliminates it as a distant foreground object and draws the ground there bright. The sphere is a
// closed mesh seen from outside, so its second layer is where the ray leaves it, and two layers
// keep everything before that exit solid (measured: RMSE on the ground 0.095 -> 0.009 for
// containment, 0.057 -> 0.015 for volumetric, 0.101 -> 0.009 for transfer's obscurance).
TEST(DepthLayers, TheGroundUnderASpheresBulgeStaysDarkWithTwoLayers) {
  Camera view;
  view.eye = {0.0f, 2.4f, 4.2f};
  view.target = {0, 0.7f, 0};
  view.vertical_fov_deg = 40.0f;
  const Mesh ground = make_quad({-6, 0, 6}, {6, 0, 6}, {6, 0, -6}, {-6, 0, -6});
  auto s = test::scene_gbuffer(scene_of({ground, make_sphere({0, 1, 0}, 1.0f, 96, 48)}), view);
  const float R = 0.35f;
  render_second_layer(*s.rays, s.g, kAutoSeparation * R);
  const Falloff f{Membership::Step, R};
  const Image<float> step = render_raytraced(*s.rays, s.g, f, {.samples = 512}, 5).visibility;
  const Image<float> sphere = render_tangent_sphere(*s.rays, s.g, R, {.samples = 512}, 5).visibility;
  Image<std::uint8_t> on_ground(s.g.width(), s.g.height(), 0);
  for (std::size_t i = 0; i < on_ground.size(); ++i) on_ground[i] = s.g.object_id[i] == 1 ? 1 : 0;
  double error[3][2];
  for (int layers = 1; layers <= 2; ++layers) {
    const DepthLayers d{layers, 0};
    error[0][layers - 1] = compare_images(containment_ao(s.g, f, {.layers = d}, 3), step, on_ground).rmse;
    error[1][layers - 1] = compare_images(volumetric_ao(s.g, R, {.layers = d}, 3), sphere, on_ground).rmse;
    error[2][layers - 1] = compare_images(transfer_ao(s.g, f, {.layers = d}, 3).obscurance, step, on_ground).rmse;
  }
  std::printf("ground beside a sphere, RMSE one layer / two: containment %.4f / %.4f, volumetric %.4f / %.4f, transfer %.4f / %.4f\n",
              error[0][0], error[0][1], error[1][0], error[1][1], error[2][0], error[2][1]);
  for (const auto& e : error) EXPECT_LT(e[1], 0.4 * e[0]);
}

// Containment's and volumetric's RMSE against their own references (step obscurance, tangent
// sphere) with one layer, with two, and with one layer's sheets R/4 thick (the second layer's
// separation), on `object` standing on a ground quad, seen from the front right and above (as
// cone_test's suite) at 640 x 360, R = 0.1 x the object's diagonal, default parameters, 128-ray
// references.
struct LayerErrors {
  double containment[3], volumetric[3];
};
LayerErrors layer_errors(const Mesh& object) {
  const Bounds3 b = object.bounds();
  const float e = b.diagonal();
  const Scene s = scene_of({object, test::ground_under(object)});
  const RayScene rs(s);
  GBuffer g = render_gbuffer(rs, frame_bounds(b, {1.0f, 0.8f, 1.3f}, 40.0f, 640, 360));
  const float R = 0.1f * e;
  render_second_layer(rs, g, kAutoSeparation * R);
  const Falloff f{Membership::Step, R};
  const Image<float> step = render_raytraced(rs, g, f, {.samples = 128}, 9).visibility;
  const Image<float> sphere = render_tangent_sphere(rs, g, R, {.samples = 128}, 9).visibility;
  const Image<std::uint8_t> mask = coverage_mask(g);
  LayerErrors out{};
  const DepthLayers configs[] = {{1, 0}, {2, 0}, {1, 0, kAutoSeparation * R}};
  for (int k = 0; k < 3; ++k) {
    ContainmentParams cp;
    VolumetricParams vp;
    cp.layers = vp.layers = configs[k];
    out.containment[k] = compare_images(containment_ao(g, f, cp, 3), step, mask).rmse;
    out.volumetric[k] = compare_images(volumetric_ao(g, R, vp, 3), sphere, mask).rmse;
  }
  return out;
}

// Issue 38's measure for the screen-space methods: on the open-mesh suite (tests/support/
// open_sheets.h: nine meshes, each a sheet or a shell with an inside, an underside or a rim seen
// against what lies behind it), containment and volumetric with two layers against their median
// error with one layer on the four closed meshes of cone_test's suite, in the same setting; on
// those closed meshes two layers are no worse than one (a closed solid's far side stays solid), and
// on the sphere and the head ellipsoid much better (the ground under their bulge, as
// TheGroundUnderASpheresBulgeStaysDarkWithTwoLayers: measured 0.13x and 0.24x for containment,
// 0.23x and 0.34x for volumetric).
// One layer takes the space under the terrain's raised edge and behind the mask for solid; two
// layers free it where the sheet does not hide it. Measured here: containment 0.40-1.48x of the
// closed median with two layers (one layer: the terrain 2.17x); volumetric 0.46-0.91x but for the
// half sphere shell 1.56x, the leaf 1.90x and the gutter 2.44x, which one layer has too (1.55x,
// 2.12x, 2.39x): for the shell and the gutter the method's own band on the ground where a convex
// wall meets it or bulges over it, which the closed sphere has too (docs/methods/depth-layers.md).
// (A suite of its own: the SIMD targets' runs, which take DepthLayers.*, would repeat its
// references for kernels the other DepthLayers tests cover.)
TEST(DepthLayersSuite, TwoLayersKeepOpenSheetsNearTheClosedMeshError) {
  std::vector<double> closed_c, closed_v;
  for (const auto& [what, m] : {std::pair{"box", make_box({-0.9f, 0.0f, -0.7f}, {0.9f, 1.0f, 0.7f})},
                                std::pair{"sphere", make_sphere({0, 1, 0}, 1.0f, 96, 48)},
                                std::pair{"torus", make_torus({0, 0.35f, 0}, 1.0f, 0.35f, 64, 24)}, std::pair{"head", test::make_head()}}) {
    const LayerErrors e = layer_errors(m);
    std::printf("%s: containment %.4f / %.4f, volumetric %.4f / %.4f\n", what, e.containment[0], e.containment[1], e.volumetric[0], e.volumetric[1]);
    const bool bulges = std::string_view(what) == "sphere" || std::string_view(what) == "head";
    EXPECT_LE(e.containment[1], (bulges ? 0.4 : 1.03) * e.containment[0]) << what;
    EXPECT_LE(e.volumetric[1], (bulges ? 0.5 : 1.03) * e.volumetric[0]) << what;
    closed_c.push_back(e.containment[0]), closed_v.push_back(e.volumetric[0]);
  }
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return 0.5 * (v[1] + v[2]);
  };
  const double mc = median(closed_c), mv = median(closed_v);
  const std::pair<const char*, Mesh> suite[] = {
      {"bent sheet with holes", test::make_holed_arch()}, {"half sphere shell", test::make_bowl()}, {"box without its top", test::make_open_box()},
      {"mask", test::make_mask()}, {"dome with a window", test::make_dome()}, {"terrain", test::make_terrain()},
      {"tablecloth", test::make_tablecloth()}, {"leaf", test::make_leaf()}, {"gutter", test::make_gutter()}};
  for (const auto& [what, open] : suite) {
    const LayerErrors e = layer_errors(open);
    std::printf("%s: containment %.4f / %.4f (%.2fx), volumetric %.4f / %.4f (%.2fx)\n", what, e.containment[0], e.containment[1],
                e.containment[1] / mc, e.volumetric[0], e.volumetric[1], e.volumetric[1] / mv);
    EXPECT_LE(e.containment[1], 1.5 * mc) << what << ": closed median " << mc;
    const std::string_view name = what;
    const double volumetric_bound = name == "half sphere shell" ? 1.6 : name == "leaf" ? 2.0 : name == "gutter" ? 2.5 : 1.5;
    EXPECT_LE(e.volumetric[1], volumetric_bound * mv) << what << ": closed median " << mv;
    if (name == "terrain" || name == "mask") {
      EXPECT_LT(e.containment[1], 0.6 * e.containment[0]) << what;
      EXPECT_LT(e.volumetric[1], 0.6 * e.volumetric[0]) << what;
      // Nothing lies behind these sheets but the ground far below, so one layer's sheets gain as
      // two layers do (measured 0.36x and 0.20x on the terrain, 0.48x and 0.24x on the mask).
      std::printf("%s, one layer's sheets R/4 thick: containment %.4f, volumetric %.4f\n", what, e.containment[2], e.volumetric[2]);
      EXPECT_LT(e.containment[2], 0.6 * e.containment[0]) << what;
      EXPECT_LT(e.volumetric[2], 0.6 * e.volumetric[0]) << what;
    }
  }
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
  // One layer's sheets need no scene (a G-buffer file or arrays): the same image with and without one.
  for (const char* name : {"containment", "volumetric", "transfer"}) {
    const MethodInfo& m = find_method(name);
    const nlohmann::json params = m.canonical_params({{"thickness", 0.4}});
    const Image<float> with_scene = run_method(MethodInput{s.g, s.rays.get(), falloff, 7}, m.decode(params)).visibility;
    const Image<float> without = run_method(MethodInput{s.g, nullptr, falloff, 7}, m.decode(params)).visibility;
    const nlohmann::json defaults = m.canonical_params(nlohmann::json::object());
    const Image<float> one_layer = run_method(MethodInput{s.g, nullptr, falloff, 7}, m.decode(defaults)).visibility;
    ASSERT_EQ(with_scene.size(), without.size());
    int brighter = 0;
    for (std::size_t i = 0; i < without.size(); ++i) {
      ASSERT_EQ(with_scene[i], without[i]) << name << ", pixel " << i;
      brighter += without[i] > one_layer[i] ? 1 : 0;
    }
    EXPECT_GT(brighter, 100) << name << ": the space behind the sheets' thickness is open where nothing hides it";
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
  p.layers = {1, 0, 0.5f};
  EXPECT_THROW(containment_ao(g, ch, Falloff{Membership::Step, 1.0f}, p, 1), InputError) << "nor sheets of a thickness";
}

}  // namespace
}  // namespace ao
