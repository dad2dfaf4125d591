// SPDX-License-Identifier: Apache-2.0
#include "ao/jobs/inputs.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ao/gbuffer/render_gbuffer.h"
#include "ao/io/mesh_io.h"
#include "ao/reference/ray_scene.h"
#include "ao/scene/procedural.h"
#include "support/scenes.h"

namespace ao {
namespace {

// Compact models that auto-framing must fill the frame with: round, with a hole, a box on a large
// ground plane (the plane does not count).
std::vector<std::pair<std::string, Scene>> compact_cases() {
  std::vector<std::pair<std::string, Scene>> cases;
  cases.emplace_back("sphere", test::scene_of({make_sphere({1, 2, 3}, 0.5f)}));
  cases.emplace_back("torus", test::scene_of({make_torus({0, 0, 0}, 1.0f, 0.25f)}));
  cases.emplace_back("box on ground", test::scene_of({make_quad({-20, 0, -20}, {-20, 0, 20}, {20, 0, 20}, {20, 0, -20}), make_box({-0.5f, 0, -0.5f}, {0.5f, 1, 0.5f})}));
  return cases;
}

// The two scanned meshes the repository carries: an elephant with its trunk raised (taller than
// wide from every side) and a dragon (long, with legs and open parts).
std::vector<std::pair<std::string, Scene>> scanned_cases() {
  std::vector<std::pair<std::string, Scene>> cases;
  const std::filesystem::path dir = AO_TEST_MESHES;
  for (const char* name : {"elephant.off", "ChineseDragon-10kv.off"}) cases.emplace_back(name, load_scene_file(dir / name));
  return cases;
}

// Everything, with shapes no view makes fill a wide image (a rod seen at an angle, a thin tower):
// all must be fitted tightly and centred.
std::vector<std::pair<std::string, Scene>> framing_cases() {
  std::vector<std::pair<std::string, Scene>> cases = compact_cases();
  for (auto& c : scanned_cases()) cases.push_back(std::move(c));
  cases.emplace_back("rod", test::scene_of({make_box({-5, -0.2f, -0.2f}, {5, 0.2f, 0.2f})}));
  cases.emplace_back("tower", test::scene_of({make_cylinder({0, 0, 0}, 0.3f, 6.0f)}));
  return cases;
}

// The fraction of a 320x180 image that `scene` covers, seen by `cam` or else by auto-framing.
double coverage(Scene scene, const std::optional<Camera>& cam = {}) {
  CameraRequest request;
  request.default_width = 320, request.default_height = 180;
  const Camera c = cam ? *cam : choose_camera(scene, request);
  const PreparedScene prepared(std::make_shared<const Scene>(std::move(scene)));
  const GBuffer g = render_gbuffer(*prepared.rays, c);
  std::size_t covered = 0;
  for (std::size_t i = 0; i < g.object_id.size(); ++i) covered += g.covered(i);
  return static_cast<double>(covered) / static_cast<double>(g.object_id.size());
}

// The measure of a readable picture: a model covers at least 30% of the frame with no camera
// options.
TEST(AutoFraming, CompactModelsCoverAtLeastThirtyPercentOfTheFrame) {
  for (auto& [name, scene] : compact_cases()) EXPECT_GE(coverage(std::move(scene)), 0.30) << name;
}

// The scanned meshes cover under half of their projected bounding rectangle, which a 16:9 image
// holds at most 0.95 high: 30% is out of reach from any view. They must cover at least twice what
// framing their bounding box from the same direction gave (the elephant: 5.6% before).
TEST(AutoFraming, ScannedMeshesCoverTwiceWhatTheBoundingBoxFramingDid) {
  for (auto& [name, scene] : scanned_cases()) {
    const Camera boxed = frame_bounds(scene.bounds(), {0.55f, 0.5f, 1.0f}, 40.0f, 320, 180);
    const double before = coverage(scene, boxed);
    EXPECT_GE(coverage(std::move(scene)), 2.0 * before) << name << ": " << before << " before";
  }
}

// Every vertex of the objects projects inside the image, the axis that limits them is 95% filled
// (the 2.5% margin on each side), and they are centred along both axes.
TEST(AutoFraming, FitsTheObjectsTightlyAndCentred) {
  for (const auto& [name, scene] : framing_cases()) {
    for (const auto& [w, h] : {std::pair{320, 180}, std::pair{100, 300}}) {
      CameraRequest request;
      request.width = w, request.height = h;
      const Camera cam = choose_camera(scene, request);
      Vec2 lo{kInfinity, kInfinity}, hi{-kInfinity, -kInfinity};
      const Mesh& m = scene.meshes.back();  // the model (the ground plane comes first)
      for (const Vec3& p : m.positions) {
        const Vec3 pc = cam.world_to_camera_point(p);
        ASSERT_LT(pc.z, 0.0f) << name;
        const Vec2 s = cam.project(pc);
        lo = {std::min(lo.x, s.x), std::min(lo.y, s.y)}, hi = {std::max(hi.x, s.x), std::max(hi.y, s.y)};
      }
      // 1e-3 of the side: float rounding of the projection.
      const float tol_x = 1e-3f * w, tol_y = 1e-3f * h;
      EXPECT_GE(lo.x, -tol_x) << name;
      EXPECT_GE(lo.y, -tol_y) << name;
      EXPECT_LE(hi.x, w + tol_x) << name;
      EXPECT_LE(hi.y, h + tol_y) << name;
      const float fill = std::max((hi.x - lo.x) / w, (hi.y - lo.y) / h);
      EXPECT_NEAR(fill, 0.95f, 2e-3f) << name << " " << w << "x" << h;
      EXPECT_NEAR(lo.x, w - hi.x, 2 * tol_x) << name << ": centred horizontally";
      EXPECT_NEAR(lo.y, h - hi.y, 2 * tol_y) << name << ": centred vertically";
    }
  }
}

TEST(AutoFraming, KeepsABuiltInScenesOwnView) {
  const Scene s = make_builtin_scene("default");
  ASSERT_TRUE(s.preferred_view.has_value());
  const Camera cam = choose_camera(s, CameraRequest{});
  EXPECT_EQ(cam.eye.x, s.preferred_view->eye.x);
  EXPECT_EQ(cam.eye.y, s.preferred_view->eye.y);
  EXPECT_EQ(cam.eye.z, s.preferred_view->eye.z);
  EXPECT_EQ(cam.target.y, s.preferred_view->target.y);
}

}  // namespace
}  // namespace ao
