// SPDX-License-Identifier: Apache-2.0
// G-buffer EXR files: exact round trips with the camera, reconstruction of what compositors leave
// out, and bad input.
#include "ao/io/gbuffer_exr.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>

#include "ao/core/error.h"
#include "support/errors.h"
#include "support/run.h"
#include "ao/io/image_io.h"

namespace ao {
namespace {

namespace fs = std::filesystem;

using test::TempDir;

Camera test_camera() {
  Camera c;
  c.eye = {1.0f, 2.0f, 5.0f};
  c.target = {0.0f, 0.5f, 0.0f};
  c.up = {0.0f, 1.0f, 0.0f};
  c.vertical_fov_deg = 50.0f;
  c.width = 48;
  c.height = 32;
  return c;
}

// A sphere in front of the camera on an empty background, built analytically in camera space:
// covered and uncovered pixels, varied normals, depths, albedo and ids.
GBuffer sphere_gbuffer(const Camera& camera) {
  GBuffer g(camera);
  const Vec3 centre{0.3f, -0.2f, -6.0f};
  const float radius = 2.0f;
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const Vec3 d = camera.camera_direction(x + 0.5f, y + 0.5f);
      // |t d - c|^2 = r^2, nearest root.
      const float a = dot(d, d), b = -2.0f * dot(d, centre), k = dot(centre, centre) - radius * radius;
      const float disc = b * b - 4 * a * k;
      if (disc < 0) continue;
      const float t = (-b - std::sqrt(disc)) / (2 * a);
      const Vec3 p = d * t;
      g.position(x, y) = p;
      g.normal(x, y) = normalize(p - centre);
      g.albedo(x, y) = {0.1f + 0.01f * x, 0.2f + 0.01f * y, 0.7f};
      g.object_id(x, y) = 1u + static_cast<unsigned>(x % 3);
    }
  }
  return g;
}

int covered_count(const GBuffer& g) {
  int n = 0;
  for (std::size_t i = 0; i < g.object_id.size(); ++i) n += g.covered(i) ? 1 : 0;
  return n;
}

void expect_near(Vec3 a, Vec3 b, float tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

TEST(GBufferExr, RoundTripKeepsEveryChannelExactly) {
  TempDir dir;
  const GBuffer g = sphere_gbuffer(test_camera());
  ASSERT_GT(covered_count(g), 100);
  ASSERT_LT(covered_count(g), g.width() * g.height());
  write_gbuffer_exr(dir / "g.exr", g);
  const GBuffer back = read_gbuffer_exr(dir / "g.exr");
  ASSERT_EQ(back.width(), g.width());
  ASSERT_EQ(back.height(), g.height());
  for (std::size_t i = 0; i < g.position.size(); ++i) {
    EXPECT_EQ(back.position[i], g.position[i]) << i;
    EXPECT_EQ(back.depth(i), g.depth(i)) << i;  // +inf background included
    EXPECT_EQ(back.albedo[i], g.albedo[i]) << i;
    EXPECT_EQ(back.object_id[i], g.object_id[i]) << i;
    EXPECT_EQ(back.covered(i), g.covered(i)) << i;
    // Renormalising an already unit normal may move it by an ulp.
    expect_near(back.normal[i], g.normal[i], 1e-6f);
  }
}

// The direct-light pass (direct.R direct.G direct.B) is optional: kept exactly when there, absent
// (empty) when not written, and written only when the G-buffer has one.
TEST(GBufferExr, DirectLightPassRoundTripsExactlyAndIsOptional) {
  TempDir dir;
  GBuffer g = sphere_gbuffer(test_camera());
  write_gbuffer_exr(dir / "none.exr", g);
  EXPECT_TRUE(read_gbuffer_exr(dir / "none.exr").direct.empty());

  g.direct = Image<Vec3>(g.width(), g.height());
  for (std::size_t i = 0; i < g.direct.size(); ++i)
    if (g.covered(i)) g.direct[i] = {0.01f * static_cast<float>(i % 97), 2.5f, 1e-8f * static_cast<float>(i)};  // > 1 is allowed
  write_gbuffer_exr(dir / "g.exr", g);
  const GBuffer back = read_gbuffer_exr(dir / "g.exr");
  ASSERT_EQ(back.direct.width(), g.width());
  ASSERT_EQ(back.direct.height(), g.height());
  for (std::size_t i = 0; i < g.direct.size(); ++i) ASSERT_EQ(back.direct[i], g.direct[i]) << "pixel " << i;

  write_gbuffer_exr(dir / "left-out.exr", g, {.direct = false});
  EXPECT_TRUE(read_gbuffer_exr(dir / "left-out.exr").direct.empty());
}

// The triangle index (primid) is optional: files without it, like those of other renderers and
// of earlier versions, read with an empty primitive_id.
TEST(GBufferExr, PrimitiveIdsRoundTripExactlyAndAreOptional) {
  TempDir dir;
  GBuffer g = sphere_gbuffer(test_camera());
  write_gbuffer_exr(dir / "none.exr", g);
  EXPECT_TRUE(read_gbuffer_exr(dir / "none.exr").primitive_id.empty());

  g.primitive_id = Image<std::uint32_t>(g.width(), g.height(), 0u);
  for (std::size_t i = 0; i < g.primitive_id.size(); ++i)
    if (g.covered(i)) g.primitive_id[i] = static_cast<std::uint32_t>(i * 2654435761u % 4000000000u);
  write_gbuffer_exr(dir / "g.exr", g);
  const GBuffer back = read_gbuffer_exr(dir / "g.exr");
  ASSERT_EQ(back.primitive_id.width(), g.width());
  for (std::size_t i = 0; i < g.primitive_id.size(); ++i) ASSERT_EQ(back.primitive_id[i], g.primitive_id[i]) << "pixel " << i;

  write_gbuffer_exr(dir / "left-out.exr", g, {.primitive_ids = false});
  EXPECT_TRUE(read_gbuffer_exr(dir / "left-out.exr").primitive_id.empty());
}

TEST(GBufferExr, BadDirectLightPassIsAnError) {
  TempDir dir;
  GBuffer g = sphere_gbuffer(test_camera());
  g.direct = Image<Vec3>(g.width(), g.height());
  ASSERT_TRUE(g.covered(24, 16));
  g.direct(24, 16).y = -0.5f;  // light is never negative
  write_gbuffer_exr(dir / "neg.exr", g);
  test::expect_one_line_error<InputError>([&] { read_gbuffer_exr(dir / "neg.exr"); }, dir / "neg.exr", "pixel (24, 16)");
  g.direct(24, 16).y = std::numeric_limits<float>::quiet_NaN();
  write_gbuffer_exr(dir / "nan.exr", g);
  test::expect_one_line_error<InputError>([&] { read_gbuffer_exr(dir / "nan.exr"); }, dir / "nan.exr", "direct radiance");
  // Background pixels are background whatever the file holds.
  ASSERT_FALSE(g.covered(0, 0));
  g.direct(24, 16).y = 0.0f;
  g.direct(0, 0) = {-1.0f, -1.0f, -1.0f};
  write_gbuffer_exr(dir / "bg.exr", g);
  EXPECT_EQ(read_gbuffer_exr(dir / "bg.exr").direct(0, 0), (Vec3{0, 0, 0}));

  // Two of the three channels: rename direct.G in the header to direct.H (same length, same
  // channel order, so the file stays readable).
  g.direct(0, 0) = {};
  write_gbuffer_exr(dir / "g.exr", g);
  std::string bytes;
  {
    std::ifstream in(dir / "g.exr", std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const std::size_t at = bytes.find(std::string("direct.G\0", 9));
  ASSERT_NE(at, std::string::npos);
  bytes[at + 7] = 'H';
  std::ofstream(dir / "partial.exr", std::ios::binary) << bytes;
  test::expect_one_line_error<InputError>([&] { read_gbuffer_exr(dir / "partial.exr"); }, dir / "partial.exr",
                                          "needs all of direct.R direct.G direct.B");
}

TEST(GBufferExr, RoundTripRecoversTheCamera) {
  TempDir dir;
  const Camera camera = test_camera();
  write_gbuffer_exr(dir / "g.exr", sphere_gbuffer(camera));
  const Camera back = read_gbuffer_exr(dir / "g.exr").camera;
  EXPECT_EQ(back.vertical_fov_deg, camera.vertical_fov_deg);
  EXPECT_EQ(back.eye, camera.eye);
  EXPECT_EQ(back.target, camera.target);
  EXPECT_EQ(back.up, camera.up);
  EXPECT_EQ(back.width, camera.width);
  EXPECT_EQ(back.height, camera.height);
}

TEST(GBufferExr, DepthAndNormalsAloneReconstructPositionsAndDefaults) {
  TempDir dir;
  const GBuffer g = sphere_gbuffer(test_camera());
  write_gbuffer_exr(dir / "zn.exr", g, {.positions = false, .albedo = false, .object_ids = false, .coverage = false});
  const GBuffer back = read_gbuffer_exr(dir / "zn.exr");
  for (int y = 0; y < g.height(); ++y) {
    for (int x = 0; x < g.width(); ++x) {
      ASSERT_EQ(back.covered(x, y), g.covered(x, y)) << x << ", " << y;
      if (!g.covered(x, y)) {
        EXPECT_EQ(back.depth(x, y), kInfinity);
        EXPECT_EQ(back.object_id(x, y), 0u);
        continue;
      }
      // Float rounding of the ray direction and the product: a few ulps, well inside 1e-4 relative.
      const Vec3 p = g.position(x, y);
      EXPECT_LE(length(back.position(x, y) - p), 1e-4f * length(p)) << x << ", " << y;
      EXPECT_EQ(back.depth(x, y), g.depth(x, y));
      EXPECT_EQ(back.albedo(x, y), (Vec3{0.8f, 0.8f, 0.8f}));
      EXPECT_EQ(back.object_id(x, y), 1u);
    }
  }
}

TEST(GBufferExr, MissingFieldOfViewAsksForFovUnlessGiven) {
  TempDir dir;
  const GBuffer g = sphere_gbuffer(test_camera());
  write_gbuffer_exr(dir / "nocam.exr", g, {.camera = false});
  test::expect_one_line_error<InputError>([&] { read_gbuffer_exr(dir / "nocam.exr"); }, dir / "nocam.exr", "--fov");

  const GBuffer back = read_gbuffer_exr(dir / "nocam.exr", {.vertical_fov_deg = 50.0f});
  EXPECT_EQ(back.camera.vertical_fov_deg, 50.0f);
  // Without a placement world space is camera space.
  EXPECT_EQ(back.camera.eye, (Vec3{0, 0, 0}));
  expect_near(back.camera.camera_to_world_point({1, 2, -3}), {1, 2, -3}, 1e-6f);
}

TEST(GBufferExr, FieldOfViewOverrideWinsOverTheFile) {
  TempDir dir;
  write_gbuffer_exr(dir / "g.exr", sphere_gbuffer(test_camera()));
  EXPECT_EQ(read_gbuffer_exr(dir / "g.exr", {.vertical_fov_deg = 30.0f}).camera.vertical_fov_deg, 30.0f);
  test::expect_one_line_error<InputError>([&] { read_gbuffer_exr(dir / "g.exr", {.vertical_fov_deg = 200.0f}); }, dir / "g.exr", "fov");
}

TEST(GBufferExr, WorldSpacePassesAreMovedIntoCameraSpace) {
  TempDir dir;
  const GBuffer g = sphere_gbuffer(test_camera());
  write_gbuffer_exr(dir / "world.exr", g, {.world_space = true});
  const GBuffer back = read_gbuffer_exr(dir / "world.exr", {.world_space = true});
  for (std::size_t i = 0; i < g.position.size(); ++i) {
    if (!g.covered(i)) continue;
    expect_near(back.position[i], g.position[i], 1e-4f * length(g.position[i]));
    expect_near(back.normal[i], g.normal[i], 1e-5f);
  }
  write_gbuffer_exr(dir / "nocam.exr", g, {.camera = false, .world_space = true});
  test::expect_one_line_error<InputError>([&] { read_gbuffer_exr(dir / "nocam.exr", {.vertical_fov_deg = 50.0f, .world_space = true}); },
                              dir / "nocam.exr", "camera placement");
}

TEST(GBufferExr, BlenderStyleHugeBackgroundDepthIsNotCovered) {
  TempDir dir;
  const GBuffer sphere = sphere_gbuffer(test_camera());
  // The background as a far surface at depth 1e10, written without A: Z = 1e10 there.
  GBuffer g = sphere;
  for (int y = 0; y < g.height(); ++y)
    for (int x = 0; x < g.width(); ++x)
      if (!g.covered(x, y)) g.position(x, y) = g.camera.camera_direction(x + 0.5f, y + 0.5f) * 1e10f, g.object_id(x, y) = 1;
  write_gbuffer_exr(dir / "g.exr", g, {.coverage = false});
  EXPECT_EQ(covered_count(read_gbuffer_exr(dir / "g.exr")), covered_count(sphere));
}

TEST(GBufferExr, NonFiniteNormalAtACoveredPixelIsAnErrorNamingThePixel) {
  TempDir dir;
  GBuffer g = sphere_gbuffer(test_camera());
  ASSERT_TRUE(g.covered(24, 16));
  g.normal(24, 16).y = std::numeric_limits<float>::quiet_NaN();
  write_gbuffer_exr(dir / "nan.exr", g);
  test::expect_one_line_error<InputError>([&] { read_gbuffer_exr(dir / "nan.exr"); }, dir / "nan.exr", "pixel (24, 16)");
}

TEST(GBufferExr, NonFinitePositionOrDepthAtACoveredPixelIsAnError) {
  TempDir dir;
  GBuffer g = sphere_gbuffer(test_camera());
  g.position(24, 16).x = kInfinity;
  write_gbuffer_exr(dir / "p.exr", g);
  test::expect_one_line_error<InputError>([&] { read_gbuffer_exr(dir / "p.exr"); }, dir / "p.exr", "pixel (24, 16)");

  g = sphere_gbuffer(test_camera());
  g.position(20, 15).z = std::numeric_limits<float>::quiet_NaN();  // Z = -P.z is NaN too
  write_gbuffer_exr(dir / "z.exr", g);  // A says covered, so the NaN depth is an error
  test::expect_one_line_error<InputError>([&] { read_gbuffer_exr(dir / "z.exr"); }, dir / "z.exr", "pixel (20, 15)");
}

// A kW x kH EXR of FLOAT channels (and `id` as UINT when given), written by hand: files ao itself
// would never write.
constexpr int kRawW = 4, kRawH = 3;
void write_raw_exr(const fs::path& path, std::vector<std::pair<const char*, std::vector<float>>> floats, std::vector<unsigned> id = {}) {
  Imf::Header header(kRawW, kRawH);
  Imf::FrameBuffer frame;
  const auto add = [&](const char* name, Imf::PixelType type, void* base, std::size_t size) {
    header.channels().insert(name, Imf::Channel(type));
    frame.insert(name, Imf::Slice(type, static_cast<char*>(base), size, size * kRawW));
  };
  for (auto& [name, plane] : floats) add(name, Imf::FLOAT, plane.data(), sizeof(float));
  if (!id.empty()) add("id", Imf::UINT, id.data(), sizeof(unsigned));
  Imf::OutputFile file(path.c_str(), header);
  file.setFrameBuffer(frame);
  file.writePixels(kRawH);
}

// Coverage is object_id != 0 and depth is -P.z (GBuffer), so a covered pixel needs an id >= 1 and
// a position in front of the camera; anything else is an error naming the pixel.
TEST(GBufferExr, CoveredPixelWithIdZeroOrPositionBehindTheCameraIsAnError) {
  TempDir dir;
  constexpr std::size_t n = kRawW * kRawH, at = 2 * kRawW + 1;  // pixel (1, 2)
  const std::vector<float> zero(n, 0.0f), one(n, 1.0f), two(n, 2.0f), minus_two(n, -2.0f);
  std::vector<unsigned> id(n, 1u);
  id[at] = 0;
  write_raw_exr(dir / "id0.exr", {{"Z", two}, {"N.X", zero}, {"N.Y", zero}, {"N.Z", one}, {"A", one}}, id);
  test::expect_one_line_error<InputError>([&] { read_gbuffer_exr(dir / "id0.exr", {.vertical_fov_deg = 40.0f}); }, dir / "id0.exr",
                                          "pixel (1, 2)");

  std::vector<float> pz = minus_two;
  pz[at] = 2.0f;  // Z says 2 in front, P says behind
  write_raw_exr(dir / "behind.exr", {{"Z", two}, {"N.X", zero}, {"N.Y", zero}, {"N.Z", one}, {"P.X", zero}, {"P.Y", zero}, {"P.Z", pz}});
  test::expect_one_line_error<InputError>([&] { read_gbuffer_exr(dir / "behind.exr", {.vertical_fov_deg = 40.0f}); }, dir / "behind.exr",
                                          "pixel (1, 2)");
  // Consistent channels read fine, and the depth is -P.z.
  write_raw_exr(dir / "ok.exr", {{"Z", two}, {"N.X", zero}, {"N.Y", zero}, {"N.Z", one}, {"P.X", zero}, {"P.Y", zero}, {"P.Z", minus_two}});
  EXPECT_EQ(read_gbuffer_exr(dir / "ok.exr", {.vertical_fov_deg = 40.0f}).depth(1, 2), 2.0f);
}

TEST(GBufferExr, NanDepthWithoutCoverageChannelIsBackground) {
  TempDir dir;
  GBuffer g = sphere_gbuffer(test_camera());
  ASSERT_TRUE(g.covered(20, 15));
  g.position(20, 15).z = std::numeric_limits<float>::quiet_NaN();  // Z = -P.z is NaN too
  write_gbuffer_exr(dir / "z.exr", g, {.coverage = false});
  const GBuffer back = read_gbuffer_exr(dir / "z.exr");
  EXPECT_FALSE(back.covered(20, 15));
  EXPECT_EQ(covered_count(back), covered_count(g) - 1);
}

TEST(GBufferExr, MissingRequiredChannelsAreListed) {
  TempDir dir;
  write_image(dir / "depth-only.exr", Image<float>(8, 8, 3.0f), {.exr_channel = "Z"});
  test::expect_one_line_error<InputError>([&] { read_gbuffer_exr(dir / "depth-only.exr", {.vertical_fov_deg = 40.0f}); },
                              dir / "depth-only.exr", "N.X N.Y N.Z");
}

TEST(GBufferExr, BadFilesAreOneLineErrors) {
  TempDir dir;
  test::expect_one_line_error<InputError>([&] { read_gbuffer_exr(dir / "missing.exr"); }, dir / "missing.exr", "does not exist");

  { std::ofstream(dir / "empty.exr"); }
  test::expect_one_line_error<InputError>([&] { read_gbuffer_exr(dir / "empty.exr"); }, dir / "empty.exr", "empty");

  write_image(dir / "image.png", Image<float>(4, 4, 0.5f));
  test::expect_one_line_error<InputError>([&] { read_gbuffer_exr(dir / "image.png"); }, dir / "image.png", "not an OpenEXR file");

  write_gbuffer_exr(dir / "g.exr", sphere_gbuffer(test_camera()));
  std::ifstream in(dir / "g.exr", std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  std::ofstream(dir / "half.exr", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  test::expect_one_line_error<InputError>([&] { read_gbuffer_exr(dir / "half.exr"); }, dir / "half.exr", "OpenEXR");
}

TEST(GBufferExr, MismatchedImageSizesAreRejectedOnWrite) {
  TempDir dir;
  GBuffer g = sphere_gbuffer(test_camera());
  g.albedo = Image<Vec3>(3, 3);
  test::expect_one_line_error<InputError>([&] { write_gbuffer_exr(dir / "g.exr", g); }, dir / "g.exr", "match");
  EXPECT_FALSE(fs::exists(dir / "g.exr"));
}

}  // namespace
}  // namespace ao
