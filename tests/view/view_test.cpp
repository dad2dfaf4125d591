// SPDX-License-Identifier: Apache-2.0
// ao view: the orbit camera's geometry, the camera file, and scripted runs in a real window under
// Xvfb (installed by scripts/setup) that must show exactly what ao render computes.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>

#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/eval/shading.h"
#include "ao/io/camera_json.h"
#include "ao/io/image_io.h"
#include "support/run.h"
#include "view/orbit.h"

namespace ao::test {
namespace {

Camera start_camera() {
  Camera c;
  c.eye = {3.0f, 2.0f, 4.0f};
  c.target = {0.5f, 0.25f, -1.0f};
  c.up = {0, 1, 0};
  c.vertical_fov_deg = 40.0f;
  c.width = 320;
  c.height = 180;
  return c;
}

float distance(Vec3 a, Vec3 b) { return length(a - b); }

TEST(ViewOrbit, StartsAtTheGivenView) {
  const Camera c = start_camera();
  const Camera o = view::OrbitCamera(c).camera(c.width, c.height);
  // The eye is rebuilt from yaw, pitch and distance: float rounding only.
  EXPECT_LT(distance(o.eye, c.eye), 1e-5f * distance(c.eye, c.target));
  EXPECT_EQ(o.target, c.target);
  EXPECT_EQ(o.vertical_fov_deg, c.vertical_fov_deg);
}

TEST(ViewOrbit, DragOfHalfTheHeightTurnsAQuarterAboutUp) {
  const Camera c = start_camera();
  view::OrbitCamera orbit(c);
  orbit.orbit(90.0f, 0.0f, 180);  // 180 px turn by pi: 90 px is a quarter turn
  const Camera o = orbit.camera(c.width, c.height);
  const Vec3 before = c.eye - c.target, after = o.eye - o.target;
  EXPECT_NEAR(after.y, before.y, 1e-4f);                          // same height above the target
  EXPECT_NEAR(before.x * after.x + before.z * after.z, 0.0f, 1e-3f);  // horizontal parts at right angles
  EXPECT_NEAR(length(after), length(before), 1e-4f);
}

TEST(ViewOrbit, PitchStopsShortOfThePole) {
  view::OrbitCamera orbit(start_camera());
  orbit.orbit(0.0f, 10000.0f, 180);
  const Camera o = orbit.camera(320, 180);
  EXPECT_NO_THROW(o.validate());  // up is never parallel to the view direction
}

TEST(ViewOrbit, ZoomAndPanKeepTheDirection) {
  const Camera c = start_camera();
  view::OrbitCamera orbit(c);
  const Vec3 dir = normalize(c.target - c.eye);
  orbit.zoom(1.0f);
  Camera o = orbit.camera(c.width, c.height);
  EXPECT_NEAR(distance(o.eye, o.target), 0.85f * distance(c.eye, c.target), 1e-4f);
  orbit.pan(30.0f, -20.0f, 180);
  o = orbit.camera(c.width, c.height);
  const Vec3 moved = o.target - c.target;
  EXPECT_GT(length(moved), 0.0f);
  EXPECT_NEAR(dot(moved, dir), 0.0f, 1e-4f);  // the target slides in the image plane
  EXPECT_LT(length(normalize(o.target - o.eye) - dir), 1e-4f);
}

// Every corner of `b` projects into the camera's image.
void expect_corners_inside(const Camera& o, const Bounds3& b) {
  for (int i = 0; i < 8; ++i) {
    const Vec3 corner{i & 1 ? b.hi.x : b.lo.x, i & 2 ? b.hi.y : b.lo.y, i & 4 ? b.hi.z : b.lo.z};
    const Vec2 p = o.project(o.world_to_camera_point(corner));
    EXPECT_GE(p.x, 0.0f) << "corner " << i;
    EXPECT_LE(p.x, static_cast<float>(o.width)) << "corner " << i;
    EXPECT_GE(p.y, 0.0f) << "corner " << i;
    EXPECT_LE(p.y, static_cast<float>(o.height)) << "corner " << i;
  }
}

TEST(ViewOrbit, FrameAllPutsEveryCornerInTheImage) {
  view::OrbitCamera orbit(start_camera());
  Bounds3 b;
  b.extend(Vec3{10, 10, 10});
  b.extend(Vec3{14, 12, 11});
  orbit.frame(b, 320, 180);
  expect_corners_inside(orbit.camera(320, 180), b);
}

TEST(ViewOrbit, FrameAllFitsANarrowImage) {
  // A tall image beside a docked panel: the box fits across its narrow width too.
  view::OrbitCamera orbit(start_camera());
  Bounds3 b;
  b.extend(Vec3{-4, 0, -1});
  b.extend(Vec3{4, 1, 1});
  orbit.frame(b, 90, 320);
  expect_corners_inside(orbit.camera(90, 320), b);
}

TEST(ViewOrbit, ZUpStaysZUp) {
  Camera c = start_camera();
  c.up = {0, 0, 1};
  view::OrbitCamera orbit(c);
  EXPECT_EQ(orbit.up_axis(), view::UpAxis::Z);
  orbit.orbit(45.0f, 0.0f, 180);
  const Camera o = orbit.camera(320, 180);
  EXPECT_EQ(o.up, (Vec3{0, 0, 1}));
  EXPECT_NEAR((o.eye - o.target).z, (c.eye - c.target).z, 1e-4f);  // orbiting about z keeps the height in z
}

TEST(CameraJson, RoundTripsBitForBit) {
  Camera c = start_camera();
  c.eye = {0.1f, 1.0f / 3.0f, -7.123456789f};
  const Camera back = camera_from_json(nlohmann::json::parse(camera_to_json(c).dump()), Camera{}, "test");
  EXPECT_EQ(back.eye, c.eye);
  EXPECT_EQ(back.target, c.target);
  EXPECT_EQ(back.up, c.up);
  EXPECT_EQ(back.vertical_fov_deg, c.vertical_fov_deg);
  EXPECT_EQ(back.width, c.width);
  EXPECT_EQ(back.height, c.height);
}

TEST(CameraJson, BadFilesAreOneLineErrors) {
  const auto bad = [](const char* text) {
    try {
      camera_from_json(nlohmann::json::parse(text), Camera{}, "cam.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(bad(R"({"eye":[0,0,5],"target":[0,0,0],"up":[0,1,0]})").find("no 'fov'"), std::string::npos);
  EXPECT_NE(bad(R"({"eye":[0,0],"target":[0,0,0],"up":[0,1,0],"fov":40})").find("'eye'"), std::string::npos);
  EXPECT_NE(bad(R"({"eye":[0,0,5],"target":[0,0,0],"up":[0,1,0],"fov":40,"zoom":2})").find("unknown camera field 'zoom'"), std::string::npos);
  EXPECT_NE(bad(R"({"eye":[0,0,5],"target":[0,0,5],"up":[0,1,0],"fov":40})").find("cam.json"), std::string::npos);
  EXPECT_NE(bad(R"({"eye":[0,0,5],"target":[0,0,0],"up":[0,1,0],"fov":40,"width":0})").find("'width'"), std::string::npos);
}

const std::string kSize = " --width 160 --height 90 ";

// The R channel of an RGB screenshot's columns from `left` on against the grey PNG ao render
// wrote, as 8-bit codes (both show display_background where no surface is visible).
int max_code_difference(const std::filesystem::path& screenshot, const std::filesystem::path& render, int left = 0) {
  const Image<Vec3> shot = read_rgb_image(screenshot);
  const Image<float> ref = read_image(render);
  EXPECT_EQ(shot.width() - left, ref.width());
  EXPECT_EQ(shot.height(), ref.height());
  if (shot.width() - left != ref.width() || shot.height() != ref.height()) return 255;
  long worst = 0;
  for (int y = 0; y < ref.height(); ++y)
    for (int x = 0; x < ref.width(); ++x)
      worst = std::max(worst, std::labs(std::lround(shot(x + left, y).x * 255) - std::lround(ref(x, y) * 255)));
  return static_cast<int>(worst);
}

int code(float v) { return static_cast<int>(std::lround(v * 255)); }

// tan of half the horizontal field of a camera file.
double horizontal_tangent(const std::filesystem::path& camera) {
  const Camera c = read_camera_file(camera, Camera{});
  return c.tan_half_fov() * c.aspect();
}

TEST(ViewCli, WithoutADisplayIsOneLineAndExitThree) {
  const RunResult r = run_ao_under("env -u DISPLAY -u WAYLAND_DISPLAY", "view" + kSize + "--frames 1");
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("no display"), std::string::npos) << r.err;
}

TEST(ViewCli, ScreenshotShowsExactlyWhatRenderComputes) {
  TempDir dir;
  // Panel and HUD hidden: the whole window is the image. The 8-bit codes are the PNG writer's
  // (lround(V * 255)), and OpenGL draws the texture unscaled and unblended, so they must agree exactly.
  const RunResult v = run_ao_under(xvfb(), "view -m containment" + kSize + "--frames 2 --set panel=off --set hud=off "
                                           "--screenshot s.png --camera-out c.json", dir.path());
  ASSERT_EQ(v.exit_code, 0) << v.err;
  const RunResult r = run_ao("render -m containment --camera c.json -o r.png", dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(max_code_difference(dir / "s.png", dir / "r.png"), 0);
}

// At 960x540, ao view's default window, the panel starts collapsed (a button in the corner) and
// must leave the picture visible; opened (--set or the P key), it docks at the left and the image
// beside it is exactly what ao render computes for the written camera, which keeps the start
// view's horizontal field.
TEST(ViewCli, ThePanelNeverCoversTheImage) {
  TempDir dir;
  const std::string view = "view -m containment --width 960 --height 540 --frames 2 --set hud=off --screenshot ";
  for (const std::string how : {"off.png --set panel=off --camera-out off.json", "default.png", "open.png --set panel=open --camera-out open.json",
                                 "key.png --event 1:key:P --camera-out key.json"}) {
    const RunResult v = run_ao_under(xvfb(), view + how, dir.path());
    ASSERT_EQ(v.exit_code, 0) << how << ": " << v.err;
  }
  // The model's pixels: those of the whole-window image that are not the background.
  const Image<Vec3> off = read_rgb_image(dir / "off.png"), shown = read_rgb_image(dir / "default.png");
  ASSERT_EQ(shown.width(), off.width());
  long model = 0, visible = 0;
  for (int y = 0; y < off.height(); ++y)
    for (int x = 0; x < off.width(); ++x) {
      if (code(off(x, y).x) == code(display_background(x, y))) continue;
      ++model;
      visible += code(shown(x, y).x) == code(off(x, y).x);
    }
  ASSERT_GT(model, 100000);  // the default scene fills most of the window
  EXPECT_GE(static_cast<double>(visible), 0.95 * static_cast<double>(model)) << visible << " of " << model;
  // Docked: the image is the window less the panel, and exactly the render of its camera.
  for (const char* name : {"open", "key"}) {
    const std::string stem(name);
    const RunResult r = run_ao("render -m containment --camera " + stem + ".json -o " + stem + "-render.png", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(read_image(dir / (stem + "-render.png")).width(), 960 - 340) << name;
    EXPECT_EQ(max_code_difference(dir / (stem + ".png"), dir / (stem + "-render.png"), 340), 0) << name;
    EXPECT_NEAR(horizontal_tangent(dir / (stem + ".json")), horizontal_tangent(dir / "off.json"), 1e-5) << name;
  }
}

TEST(ViewCli, BenchmarkAccumulatesTheReferenceOnRequest) {
  // --benchmark recomputes every frame, so nothing accumulates: --wait-reference cannot wait for it.
  const RunResult bench = run_ao_under(xvfb(), "view" + kSize + "--frames 2 --benchmark --wait-reference 8 --json");
  ASSERT_EQ(bench.exit_code, 0) << bench.err;
  EXPECT_EQ(nlohmann::json::parse(bench.out)["reference"]["samples_per_pixel"].get<int>(), 0);
  // reference=on pauses the benchmark and accumulates it.
  const RunResult asked = run_ao_under(xvfb(), "view" + kSize + "--frames 2 --benchmark --set reference=on --wait-reference 8 --json");
  ASSERT_EQ(asked.exit_code, 0) << asked.err;
  EXPECT_EQ(nlohmann::json::parse(asked.out)["reference"]["samples_per_pixel"].get<int>(), 8);
}

TEST(ViewCli, SetAndScriptedInputChangeTheImageAsOfflineOptionsDo) {
  TempDir dir;
  // --set and a scripted set at frame 1 both equal -p offline.
  for (const std::string how : {"--set samples=4", "--event 1:set:samples=4"}) {
    const RunResult v = run_ao_under(xvfb(), "view -m volumetric" + kSize + "--frames 3 --set panel=off --set hud=off " + how + " --screenshot s.png",
                                     dir.path());
    ASSERT_EQ(v.exit_code, 0) << v.err;
    const RunResult r = run_ao("render -m volumetric" + kSize + "-p samples=4 -o r.png", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(max_code_difference(dir / "s.png", dir / "r.png"), 0) << how;
  }
  // A scripted drag orbits the camera; the written camera renders the same image offline.
  const RunResult v = run_ao_under(xvfb(), "view -m volumetric" + kSize + "--frames 3 --set panel=off --set hud=off --event 1:orbit:30,-10 "
                                           "--event 2:zoom:1 --screenshot moved.png --camera-out c.json", dir.path());
  ASSERT_EQ(v.exit_code, 0) << v.err;
  const RunResult r = run_ao("render -m volumetric --camera c.json -o moved-render.png", dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(max_code_difference(dir / "moved.png", dir / "moved-render.png"), 0);
  EXPECT_GT(max_code_difference(dir / "moved.png", dir / "r.png"), 0);  // and it did move
}

TEST(ViewCli, ReferenceStandardErrorFallsAsItAccumulates) {
  TempDir dir;
  auto state = [&](int spp) {
    const RunResult r = run_ao_under(xvfb(), "view -m containment" + kSize + "--frames 2 --json --wait-reference " + std::to_string(spp), dir.path());
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return nlohmann::json::parse(r.out)["reference"];
  };
  // A scripted run stops accumulating at --wait-reference, so the counts are exact.
  const nlohmann::json few = state(8), many = state(128);
  EXPECT_EQ(few["samples_per_pixel"].get<int>(), 8);
  EXPECT_EQ(many["samples_per_pixel"].get<int>(), 128);
  // Independent batches: the standard error of their mean falls like 1/sqrt(batches), here by 4x
  // (2 batches against 32). The two-batch estimate of it is itself noisy (and the batch means of a
  // few step-membership rays are far from normal), so ask only for a fall below 0.6x.
  EXPECT_LT(many["mean_std_error"].get<double>(), 0.6 * few["mean_std_error"].get<double>());
  EXPECT_GT(few["rmse"].get<double>(), 0.0);
  // One batch (4 rays) allows no estimate: null, not 0 (which would read as converged).
  const nlohmann::json one = state(4);
  EXPECT_EQ(one["batches"].get<int>(), 1);
  EXPECT_TRUE(one["mean_std_error"].is_null());
}

TEST(ViewCli, BadSettingsAreOneLineErrors) {
  for (const char* args : {"--set view=sideways", "--set scale=3", "--set nonsense=1", "--set panel=docked", "--set reference=yes", "--event 1:twist:3",
                           "--screenshot x.png"}) {
    const RunResult r = run_ao_under(xvfb(), "view" + kSize + args);
    EXPECT_EQ(r.exit_code, 1) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  }
}

}  // namespace
}  // namespace ao::test
