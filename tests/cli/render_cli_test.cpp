// SPDX-License-Identifier: Apache-2.0
// `ao render` as users and scripts meet it: outputs, JSON, exit codes, and bad input that gets a
// one-line error, a non-zero exit and no output (SPEC, "Behaviour on bad input").
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/eval/shading.h"
#include "ao/io/gbuffer_exr.h"
#include "ao/io/image_io.h"
#include "support/run.h"

namespace ao::test {
namespace {

const std::string kSmall = " --width 40 --height 30 --spp 16 ";

// One line on stderr, starting "ao: error:", that mentions `needle`.

TEST(RenderCli, DefaultSceneWritesImageAndJsonSummary) {
  TempDir dir;
  const RunResult r = run_ao("render" + kSmall + "-o v.exr --shaded s.png --gbuffer-out g.exr --json", dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"v.exr", "s.png", "g.exr"}) EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["scene"], "default");
  EXPECT_EQ(j["method"], "raytraced");
  EXPECT_EQ(j["width"], 40);
  EXPECT_EQ(j["parameters"]["samples"], 16);
  EXPECT_EQ(j["membership"], "step");
  EXPECT_GT(j["radius"].get<double>(), 0.0);
  EXPECT_GT(j["mean_visibility"].get<double>(), 0.0);
  EXPECT_LE(j["mean_visibility"].get<double>(), 1.0);
  EXPECT_GT(j["stats"]["rays"].get<double>(), 0.0);
  EXPECT_GE(j["stats"]["max_std_error"].get<double>(), j["stats"]["mean_std_error"].get<double>());
  for (const char* t : {"load_ms", "bvh_ms", "gbuffer_ms", "ao_ms", "write_ms"}) EXPECT_TRUE(j["timings"].contains(t)) << t;
}

// The check of a readable picture: a lone mesh with no camera options covers at least 30%
// of the frame, and its background is not white: the V PNG and --shaded show display_background
// there; the EXR keeps V = 1 (data).
TEST(RenderCli, LoneMeshFillsTheFrameAndItsBackgroundIsNotOpenSurface) {
  TempDir dir;
  dir.write("cube.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                        "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n");
  const RunResult r = run_ao("render cube.obj --width 160 --height 90 --spp 4 -o v.png --shaded s.png --gbuffer-out g.exr", dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_EQ(run_ao("render cube.obj --width 160 --height 90 --spp 4 -o v.exr", dir.path()).exit_code, 0);
  const StoredPng v = read_stored_png(dir / "v.png"), shaded = read_stored_png(dir / "s.png");
  const Image<float> data = read_image(dir / "v.exr");
  const GBuffer g = read_gbuffer_exr(dir / "g.exr");
  ASSERT_EQ(v.channels, 1);
  ASSERT_EQ(shaded.channels, 3);
  std::size_t covered = 0, background = 0;
  for (int y = 0; y < 90; ++y)
    for (int x = 0; x < 160; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * 160 + x;
      if (g.covered(i)) {
        ++covered;
        continue;
      }
      ++background;
      EXPECT_EQ(v.samples[i], static_cast<unsigned>(std::lround(255 * display_background(x, y)))) << x << "," << y;
      EXPECT_EQ(data[i], 1.0f) << "EXR: V = 1 on the background";
      EXPECT_LT(shaded.samples[3 * i], 255u) << "the shaded background is not white";
    }
  EXPECT_GE(static_cast<double>(covered) / (160.0 * 90.0), 0.30);
  EXPECT_GT(background, 0u);
}

TEST(RenderCli, WithoutOutputNamesTheFileAfterSceneAndMethod) {
  TempDir dir;
  const RunResult r = run_ao("render plane" + kSmall, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "plane-raytraced.png"));
  EXPECT_NE(r.err.find("wrote plane-raytraced.png"), std::string::npos) << r.err;
}

TEST(RenderCli, RadiusCanBeGivenInWorldUnitsOrAsAFraction) {
  TempDir dir;
  auto radius = [&](const std::string& opt) {
    const RunResult r = run_ao("render sphere-on-plane" + kSmall + "-o v.png --json " + opt, dir.path());
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return nlohmann::json::parse(r.out)["radius"].get<double>();
  };
  EXPECT_NEAR(radius("--radius 0.75"), 0.75, 1e-6);
  EXPECT_NEAR(radius("--radius-fraction 0.2"), 2.0 * radius("--radius-fraction 0.1"), 1e-5);
}

TEST(RenderCli, CameraOptionsOverrideTheFraming) {
  TempDir dir;
  const RunResult r = run_ao("render plane" + kSmall + "-o v.png --json --eye 0,5,5 --target 0,0,0 --fov 30", dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto cam = nlohmann::json::parse(r.out)["camera"];
  EXPECT_EQ(cam["eye"], nlohmann::json::array({0.0, 5.0, 5.0}));
  EXPECT_EQ(cam["fov"], 30.0);
}

TEST(RenderCli, GBufferFileFeedsScreenSpaceMethodsButNotTheRayTracer) {
  TempDir dir;
  ASSERT_EQ(run_ao("render" + kSmall + "-o v.png --gbuffer-out g.exr", dir.path()).exit_code, 0);
  const RunResult r = run_ao("render --gbuffer-in g.exr -o w.png", dir.path());
  EXPECT_EQ(r.exit_code, 1);
  expect_one_line_error(r, "--gbuffer-in");
  EXPECT_FALSE(std::filesystem::exists(dir / "w.png"));
}

TEST(RenderCli, AoMapIsShownThroughTheMeshUvs) {
  TempDir dir;
  // A unit quad facing +y with UVs over the whole map; left half of the map 0.2, right half 0.8.
  write_text(dir / "quad.obj",
             "v 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
  Image<float> map(64, 64, 0.2f);
  for (int y = 0; y < 64; ++y)
    for (int x = 32; x < 64; ++x) map(x, y) = 0.8f;
  write_image(dir / "map.exr", map);
  const RunResult r = run_ao("render quad.obj --ao-map map.exr --eye 0.5,2,-0.5 --target 0.5,0,-0.5 --up 0,0,-1 --fov 20 --width 64 --height 64 -o v.exr --json",
                             dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["method"], "ao-map");
  // The quad fills the view's middle; u grows with world x, which is image x here.
  const Image<float> v = read_image(dir / "v.exr");
  EXPECT_NEAR(v(24, 32), 0.2f, 1e-5f);
  EXPECT_NEAR(v(40, 32), 0.8f, 1e-5f);
}

TEST(RenderCli, AoMapNeedsUvs) {
  TempDir dir;
  write_image(dir / "map.png", Image<float>(4, 4, 0.5f));
  const RunResult r = run_ao("render plane --ao-map map.png -o v.png", dir.path());
  EXPECT_EQ(r.exit_code, 1);
  expect_one_line_error(r, "no UVs");
  EXPECT_FALSE(std::filesystem::exists(dir / "v.png"));
}

// A compositor's path: the G-buffer written by one run feeds a screen-space method in another, and
// gives the same image as running the method on the scene directly (the EXR keeps floats exactly).
// R is given: by default it is a fraction of the scene's diagonal, and a G-buffer file only knows
// the visible points' bounds.
TEST(RenderCli, GBufferRoundTripGivesTheSameScreenSpaceImage) {
  TempDir dir;
  ASSERT_EQ(run_ao("render sphere-on-plane --width 64 --height 48 --method volumetric -R 0.5 -o direct.exr --gbuffer-out g.exr", dir.path()).exit_code, 0);
  const RunResult r = run_ao("render --gbuffer-in g.exr --method volumetric -R 0.5 -o fromfile.exr --json", dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["width"], 64);
  const Image<float> a = read_image(dir / "direct.exr"), b = read_image(dir / "fromfile.exr");
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << "pixel " << i;
}

// VAO fig. 12 from the command line: the displaced floor's height field times the depth buffer.
// The '*' is quoted as a shell user would; the JSON echoes the choice and what ran.
TEST(RenderCli, CharacteristicParameterChoosesThePapersOtherFunctions) {
  TempDir dir;
  const auto mean_v = [&](const std::string& args) {
    const RunResult r = run_ao("render displaced --width 64 --height 36 --method volumetric --json " + args, dir.path());
    EXPECT_EQ(r.exit_code, 0) << args << ": " << r.err;
    return nlohmann::json::parse(r.out);
  };
  const auto depth = mean_v("-o depth.png");
  const auto both = mean_v("-p 'characteristic=depth*height-field' -o x.png");
  EXPECT_TRUE(std::filesystem::exists(dir / "x.png"));
  EXPECT_EQ(depth["parameters"]["characteristic"], "depth");
  EXPECT_EQ(both["parameters"]["characteristic"], "depth*height-field");
  EXPECT_EQ(both["stats"]["characteristic"], "depth*height-field");
  EXPECT_LT(both["mean_visibility"].get<double>(), depth["mean_visibility"].get<double>());
  const RunResult r = run_ao("render wedge --width 32 --height 24 -m containment -p characteristic=implicit -R 0.5 -o w.png", dir.path());
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

TEST(RenderCli, CharacteristicTheSceneCannotProvideIsAnInputError) {
  TempDir dir;
  ASSERT_EQ(run_ao("render wedge --width 32 --height 24 -m containment -o v.png --gbuffer-out g.exr", dir.path()).exit_code, 0);
  const std::pair<std::string, const char*> cases[] = {
      {"wedge -m containment -p characteristic=height-field", "displaced"},
      {"displaced -m transfer -p characteristic=implicit", "sphere-on-plane"},
      {"--gbuffer-in g.exr -m volumetric -p characteristic=implicit", "--gbuffer-in"},
      {"--gbuffer-in g.exr -m containment -p 'characteristic=depth*height-field'", "--gbuffer-in"},
      {"plane -m volumetric -p characteristic=zbuffer", "zbuffer"},
  };
  for (const auto& [args, needle] : cases) {
    const RunResult r = run_ao("render " + args + " --width 32 --height 24 -o out.png", dir.path());
    EXPECT_EQ(r.exit_code, 1) << args << ": " << r.err;
    expect_one_line_error(r, needle);
    EXPECT_FALSE(std::filesystem::exists(dir / "out.png")) << args;
  }
}

// --sun computes the direct-light pass; transfer's radiance mode reads it and --shaded adds it.
TEST(RenderCli, SunFeedsTransfersRadianceModeAndTheShadedImage) {
  TempDir dir;
  const RunResult r =
      run_ao("render --width 64 --height 48 -m transfer --sun 1,2,1 -p reflectance=radiance --shaded s.png -o v.exr --json", dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "s.png"));
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["parameters"]["reflectance"], "radiance");
  const float k = 1.0f / std::sqrt(6.0f);  // (1, 2, 1), normalised
  EXPECT_NEAR(j["sun"]["direction"][0].get<double>(), k, 1e-6);
  EXPECT_NEAR(j["sun"]["direction"][1].get<double>(), 2 * k, 1e-6);
  EXPECT_NEAR(j["sun"]["irradiance"].get<double>(), 3.14159265, 1e-6);  // default: pi, as bright as the sky
  EXPECT_TRUE(j["timings"].contains("direct_ms"));
}

// E = 0: no direct light, so the radiance mode is eq. 9 and gives the albedo mode's image exactly.
TEST(RenderCli, SunOfZeroIrradianceLeavesTransferUnchanged) {
  TempDir dir;
  const std::string common = "render --width 64 --height 48 -m transfer -R 0.5 ";
  ASSERT_EQ(run_ao(common + "-o albedo.exr", dir.path()).exit_code, 0);
  const RunResult r = run_ao(common + "--sun 0,1,0,0 -p reflectance=radiance -o radiance.exr", dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image<float> a = read_image(dir / "albedo.exr"), b = read_image(dir / "radiance.exr");
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << "pixel " << i;
}

// A compositor's path with a direct pass: the G-buffer EXR carries direct.*, and the radiance mode
// on the file gives the image of the run that computed it.
TEST(RenderCli, DirectPassRoundTripsThroughTheGBufferFile) {
  TempDir dir;
  const std::string method = " -m transfer -p reflectance=radiance -R 0.5 ";
  ASSERT_EQ(run_ao("render --width 64 --height 48 --sun 1,2,1,2" + method + "-o direct.exr --gbuffer-out g.exr", dir.path()).exit_code, 0);
  const RunResult r = run_ao("render --gbuffer-in g.exr" + method + "-o fromfile.exr", dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image<float> a = read_image(dir / "direct.exr"), b = read_image(dir / "fromfile.exr");
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << "pixel " << i;
}

TEST(RenderCli, RadianceModeWithoutADirectPassSaysHowToGetOne) {
  TempDir dir;
  RunResult r = run_ao("render" + kSmall + "-m transfer -p reflectance=radiance -o v.png", dir.path());
  EXPECT_EQ(r.exit_code, 1);
  expect_one_line_error(r, "--sun");
  EXPECT_FALSE(std::filesystem::exists(dir / "v.png"));
  ASSERT_EQ(run_ao("render" + kSmall + "-m transfer -o v.png --gbuffer-out g.exr", dir.path()).exit_code, 0);
  std::filesystem::remove(dir / "v.png");
  r = run_ao("render --gbuffer-in g.exr -m transfer -p reflectance=radiance -o v.png", dir.path());
  EXPECT_EQ(r.exit_code, 1);
  expect_one_line_error(r, "direct.R direct.G direct.B");
  EXPECT_FALSE(std::filesystem::exists(dir / "v.png"));
  r = run_ao("render --gbuffer-in g.exr -m transfer --sun 0,1,0 -o v.png", dir.path());
  EXPECT_EQ(r.exit_code, 1);
  expect_one_line_error(r, "--sun traces shadow rays in the scene");
  r = run_ao("render" + kSmall + "-m transfer -p reflectance=sunny -o v.png", dir.path());
  EXPECT_EQ(r.exit_code, 1);
  expect_one_line_error(r, "reflectance");
}

TEST(RenderCli, BadSunsAreOneLineErrors) {
  TempDir dir;
  for (const auto& [sun, needle] : std::vector<std::pair<std::string, std::string>>{{"0,0,0", "no length"},
                                                                                   {"1,nan,0", "not a finite"},
                                                                                   {"1,inf,0", "not a finite"},
                                                                                   {"1e39,0,0", "not a finite"},
                                                                                   {"0,1,0,-1", ">= 0"},
                                                                                   {"0,1,0,inf", "not a finite"},
                                                                                   {"1,2", "3 or 4 numbers"},
                                                                                   {"1,2,3,4,5", "3 or 4 numbers"},
                                                                                   {"1,2,3,", "not a number"},
                                                                                   {"x,1,0", "not a number"},
                                                                                   {"1,,0", "not a number"}}) {
    const RunResult r = run_ao("render plane" + kSmall + "-m transfer --sun=" + sun + " -o v.png", dir.path());
    EXPECT_EQ(r.exit_code, 1) << sun << ": " << r.err;
    expect_one_line_error(r, needle);
    EXPECT_FALSE(std::filesystem::exists(dir / "v.png")) << sun;
  }
}

TEST(RenderCli, MissingMeshIsAnInputError) {
  TempDir dir;
  const RunResult r = run_ao("render nowhere.obj -o v.png", dir.path());
  EXPECT_EQ(r.exit_code, 1);
  expect_one_line_error(r, "nowhere.obj");
  EXPECT_FALSE(std::filesystem::exists(dir / "v.png"));
}

TEST(RenderCli, UnknownSceneListsTheBuiltins) {
  const RunResult r = run_ao("render teapot");
  EXPECT_EQ(r.exit_code, 1);
  expect_one_line_error(r, "sphere-on-plane");
}

TEST(RenderCli, MalformedMeshesFailWithoutOutputAndKeepExistingFiles) {
  TempDir dir;
  write_text(dir / "keep.png", "previous contents");
  const std::pair<const char*, const char*> cases[] = {
      {"truncated.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n"},
      {"nan.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n"},
      {"index.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"},
      {"huge.off", "OFF\n2000000000 2000000000 0\n0 0 0\n"},
      {"degenerate.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n"},
      {"garbage.obj", "\x7f\x01\x02 this is not a mesh\n"},
      {"empty.stl", ""},
  };
  for (const auto& [name, text] : cases) {
    write_text(dir / name, text);
    const RunResult r = run_ao(std::string("render ") + name + " -o keep.png", dir.path());
    EXPECT_EQ(r.exit_code, 1) << name << ": " << r.err;
    expect_one_line_error(r, name);
    EXPECT_EQ(read_text(dir / "keep.png"), "previous contents") << name;
  }
  // Nothing but the inputs and the untouched file: no temporary files left behind.
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++files;
  EXPECT_EQ(files, std::size(cases) + 1);
}

TEST(RenderCli, AbsurdOptionsAreInputErrors) {
  TempDir dir;
  const std::pair<const char*, const char*> cases[] = {
      {"--width 100000", "--width must be in [1, 32768] pixels, got 100000"},
      {"--height 0", "--height must be in [1, 32768] pixels, got 0"},
      {"--spp 0", "samples"},
      {"--spp 100000000", "samples"},
      {"--target-error -1", "target_error"},
      {"--radius -2", "radius"},
      {"--fov 200", "fov"},
      {"--membership cosine", "cosine"},
      {"--method magic", "magic"},
      {"--eye 1,2", "--eye"},
      {"--eye 0,0,0 --target 0,0,0", "same point"},
      {"-p bogus=1", "bogus"},
      {"--png-bits 12", "png-bits"},
  };
  for (const auto& [opt, needle] : cases) {
    const RunResult r = run_ao(std::string("render plane -o v.png ") + opt, dir.path());
    EXPECT_EQ(r.exit_code, 1) << opt << ": " << r.err;
    expect_one_line_error(r, needle);
    EXPECT_FALSE(std::filesystem::exists(dir / "v.png")) << opt;
  }
}

TEST(RenderCli, UnwritableOutputIsAnErrorNamingIt) {
  TempDir dir;
  const RunResult r = run_ao("render plane" + kSmall + "-o missing-dir/v.png", dir.path());
  EXPECT_NE(r.exit_code, 0);
  expect_one_line_error(r, "missing-dir");
}

TEST(RenderCli, UnknownExtensionIsRejected) {
  TempDir dir;
  const RunResult r = run_ao("render plane" + kSmall + "-o v.bmp", dir.path());
  EXPECT_EQ(r.exit_code, 1);
  expect_one_line_error(r, ".png");
}

TEST(RenderCli, UsageErrorsExitWithTwo) {
  EXPECT_EQ(run_ao("render --no-such-option").exit_code, 2);
  EXPECT_EQ(run_ao("").exit_code, 2);
  EXPECT_EQ(run_ao("render --help").exit_code, 0);
}

// Default R comes from the objects, not the ground they stand on: a box alone and the same box
// on a quad 100 times its size get the same R (0.1 x the box's diagonal, sqrt(3) here).
TEST(RenderCli, DefaultRadiusIgnoresAFlatGround) {
  TempDir dir;
  std::ofstream(dir / "box.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                                    "f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 4 8 7\nf 4 7 3\nf 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n";
  std::ofstream(dir / "ground.obj") << "v -50 0 -50\nv 50 0 -50\nv 50 0 50\nv -50 0 50\nf 1 3 2\nf 1 4 3\n";
  auto radius = [&](const std::string& scene) {
    const RunResult r = run_ao("render " + scene + kSmall + "-o v.png --json", dir.path());
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return nlohmann::json::parse(r.out)["radius"].get<double>();
  };
  EXPECT_NEAR(radius("box.obj"), 0.1 * std::sqrt(3.0), 1e-5);
  EXPECT_NEAR(radius("box.obj ground.obj"), 0.1 * std::sqrt(3.0), 1e-5);
  EXPECT_NEAR(radius("ground.obj"), 0.1 * 100 * std::sqrt(2.0), 1e-3) << "all flat: the whole scene";
  const RunResult r = run_ao("render box.obj ground.obj" + kSmall + "-o v.png", dir.path());
  EXPECT_NE(r.err.find("R = 0.1732"), std::string::npos) << "the summary line states R: " << r.err;
}

TEST(RenderCli, NormalOptionChoosesTheGBufferNormal) {
  TempDir dir;
  for (const char* n : {"shading", "geometric"}) {
    const RunResult r = run_ao("render sphere-on-plane" + kSmall + "-o v.png --json --normal " + n, dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["normal"], n);
  }
  const RunResult bad = run_ao("render plane -o bad.png --normal smooth", dir.path());
  EXPECT_EQ(bad.exit_code, 1);
  expect_one_line_error(bad, "--normal");
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.png"));
}

}  // namespace
}  // namespace ao::test
