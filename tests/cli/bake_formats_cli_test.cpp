// SPDX-License-Identifier: Apache-2.0
// `ao bake` output formats as a pipeline meets them: non-square maps, ORM packing, TGA/TIFF/JPEG,
// UDIM tiles, glTF outputs. Meshes are tiny OBJ files written here; maps are a few dozen texels.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <sstream>

#include <nlohmann/json.hpp>

#include "ao/io/image_io.h"
#include "ao/io/mesh_io.h"
#include "support/run.h"

namespace ao::test {
namespace {

namespace fs = std::filesystem;

const std::string kRays = " -m raytraced --samples 8 --padding 2 ";

// A unit quad in the xz-plane facing up (V = 1 everywhere: every ray leaves into the open
// hemisphere) whose UVs cover [u0, u1] x [v0, v1].
std::string quad_obj(double u0, double v0, double u1, double v1, const std::string& name = "quad") {
  std::ostringstream s;
  s << "o " << name << "\nv 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\nvn 0 1 0\n";
  s << "vt " << u0 << " " << v0 << "\nvt " << u1 << " " << v0 << "\nvt " << u1 << " " << v1 << "\nvt " << u0 << " " << v1 << "\n";
  s << "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n";
  return s.str();
}


std::uint32_t be32(const std::string& s, std::size_t at) {
  return (static_cast<std::uint32_t>(static_cast<unsigned char>(s[at])) << 24) | (static_cast<std::uint32_t>(static_cast<unsigned char>(s[at + 1])) << 16) |
         (static_cast<std::uint32_t>(static_cast<unsigned char>(s[at + 2])) << 8) | static_cast<std::uint32_t>(static_cast<unsigned char>(s[at + 3]));
}

// --- non-square maps ---------------------------------------------------------------------------

TEST(BakeFormats, NonSquareSizeGoesToEveryPerTexelOutput) {
  TempDir dir;
  // The quad fills the left half of the UV square: on a 32 x 8 map, columns 0..15.
  write_text(dir / "quad.obj", quad_obj(0, 0, 0.5, 1));
  const RunResult r = run_ao("bake quad.obj -s 32x8 -o ao.png --bent-normals bent.exr --gltf m.glb --json" + kRays, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["width"], 32);
  EXPECT_EQ(j["height"], 8);
  EXPECT_FALSE(j.contains("size"));
  EXPECT_EQ(j["texels_covered"], 16 * 8);
  const Image<float> map = read_image(dir / "ao.png");
  ASSERT_EQ(map.width(), 32);
  ASSERT_EQ(map.height(), 8);
  // Open quad: V = 1 on the chart; padding (2 texels) reaches columns 16, 17 only.
  EXPECT_EQ(map(3, 3), 1.0f);
  EXPECT_EQ(map(17, 3), 1.0f);
  EXPECT_EQ(map(25, 3), 0.0f);
  const Image<Vec3> bent = read_rgb_image(dir / "bent.exr");
  EXPECT_EQ(bent.width(), 32);
  EXPECT_EQ(bent.height(), 8);
  // The map embedded in the GLB has the same size (PNG IHDR: width, height after "IHDR").
  const std::string glb = read_text(dir / "m.glb");
  const std::size_t png = glb.find("\x89PNG\r\n\x1a\n");
  ASSERT_NE(png, std::string::npos);
  EXPECT_EQ(be32(glb, png + 16), 32u);
  EXPECT_EQ(be32(glb, png + 20), 8u);
}

TEST(BakeFormats, NonSquareWithTheHistogramBaker) {
  TempDir dir;
  write_text(dir / "quad.obj", quad_obj(0, 0, 1, 1));
  const RunResult r = run_ao("bake quad.obj -m histogram -s 8x24 --directions 32 --pixels-per-texel 4 -o ao.exr --json", dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image<float> map = read_image(dir / "ao.exr");
  EXPECT_EQ(map.width(), 8);
  EXPECT_EQ(map.height(), 24);
  EXPECT_EQ(nlohmann::json::parse(r.out)["texels_covered"], 8 * 24);
}

TEST(BakeFormats, SquareSizeStillTakesOneNumber) {
  TempDir dir;
  write_text(dir / "quad.obj", quad_obj(0, 0, 1, 1));
  const RunResult r = run_ao("bake quad.obj -s 12 -o ao.png --json" + kRays, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["size"], 12);
  EXPECT_EQ(read_image(dir / "ao.png").height(), 12);
}

TEST(BakeFormats, BadSizesAreOneLineErrors) {
  TempDir dir;
  write_text(dir / "quad.obj", quad_obj(0, 0, 1, 1));
  for (const char* bad : {"0", "16x", "x16", "16x0", "16385x4", "4x16385", "abc", "16x8x2", "-4", "1e3", "99999999999"}) {
    expect_one_line_error(run_ao(std::string("bake quad.obj -o ao.png -s ") + bad, dir.path()), "--size");
    EXPECT_FALSE(fs::exists(dir / "ao.png")) << bad;
  }
}

// --- --orm ---------------------------------------------------------------------------------------

// A W x H ORM texture whose G, B (and A) vary per pixel, so any shuffling shows.
StoredPng orm_texture(int w, int h, int channels, int bits) {
  StoredPng t{w, h, channels, bits, {}};
  const int max = bits == 16 ? 65535 : 255;
  for (int i = 0; i < w * h; ++i)
    for (int c = 0; c < channels; ++c) t.samples.push_back(static_cast<std::uint16_t>((i * 37 + c * 101) % (max + 1)));
  return t;
}

TEST(BakeFormats, OrmGetsAoInRedAndKeepsEverythingElse) {
  for (const auto& [channels, bits] : {std::pair{4, 16}, std::pair{3, 8}}) {
    TempDir dir;
    write_text(dir / "quad.obj", quad_obj(0, 0, 0.5, 1));
    const StoredPng orm = orm_texture(16, 8, channels, bits);
    write_stored_png(dir / "orm.png", orm);
    const std::string before = read_text(dir / "orm.png");
    // No -s: the map takes the texture's size (16 x 8).
    const RunResult r = run_ao("bake quad.obj --orm orm.png -o packed.png --json" + kRays, dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["width"], 16);
    EXPECT_EQ(read_text(dir / "orm.png"), before);  // the input is never modified
    const StoredPng out = read_stored_png(dir / "packed.png");
    ASSERT_EQ(out.width, 16);
    ASSERT_EQ(out.height, 8);
    ASSERT_EQ(out.channels, channels);
    ASSERT_EQ(out.bits, bits);
    const int max = bits == 16 ? 65535 : 255;
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 16; ++x) {
        const std::size_t i = static_cast<std::size_t>(y * 16 + x) * static_cast<std::size_t>(channels);
        for (int c = 1; c < channels; ++c) EXPECT_EQ(out.samples[i + static_cast<std::size_t>(c)], orm.samples[i + static_cast<std::size_t>(c)]) << x << "," << y << " channel " << c;
        // The open quad covers columns 0..7 (V = 1 exactly); padding (2) reaches 8, 9; beyond, V = 0.
        if (x < 10) {
          EXPECT_EQ(out.samples[i], max) << x << "," << y;
        } else if (x > 11) {
          EXPECT_EQ(out.samples[i], 0) << x << "," << y;
        }
      }
  }
}

TEST(BakeFormats, OrmMisuseIsAOneLineErrorAndWritesNothing) {
  TempDir dir;
  write_text(dir / "quad.obj", quad_obj(0, 0, 1, 1));
  write_stored_png(dir / "orm.png", orm_texture(16, 8, 3, 8));
  write_stored_png(dir / "grey.png", orm_texture(16, 8, 1, 8));
  const std::string before = read_text(dir / "orm.png");
  expect_one_line_error(run_ao("bake quad.obj --orm orm.png -s 16 -o out.png" + kRays, dir.path()), "give --size 16x8 or leave it unset");
  expect_one_line_error(run_ao("bake quad.obj --orm grey.png -o out.png" + kRays, dir.path()), "greyscale");
  expect_one_line_error(run_ao("bake quad.obj --orm orm.png -o out.exr" + kRays, dir.path()), ".png");
  expect_one_line_error(run_ao("bake quad.obj --orm orm.png --png-bits 16 -o out.png" + kRays, dir.path()), "--png-bits");
  expect_one_line_error(run_ao("bake quad.obj --orm missing.png -o out.png" + kRays, dir.path()), "missing.png");
  expect_one_line_error(run_ao("bake quad.obj --orm quad.obj -o out.png" + kRays, dir.path()), "quad.obj");
  expect_one_line_error(run_ao("bake quad.obj quad.obj --orm orm.png" + kRays, dir.path()), "one mesh");
  // Writing over the ORM texture itself is refused before any work: it is an input.
  expect_one_line_error(run_ao("bake quad.obj --orm orm.png -o orm.png" + kRays, dir.path()), "orm.png");
  EXPECT_EQ(read_text(dir / "orm.png"), before);
  EXPECT_FALSE(fs::exists(dir / "out.png"));
  EXPECT_FALSE(fs::exists(dir / "out.exr"));
}

// --- UDIM ----------------------------------------------------------------------------------------

// Two quads in two UDIM tiles: a floor (y = 0, facing up) with UVs in tile 1001 and, `gap` above
// it, a roof (facing down) with UVs in tile 1002. Each occludes the other.
std::string two_tile_obj(double gap) {
  std::ostringstream s;
  s << "o floor\nv 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\nvn 0 1 0\n";
  s << "vt 0.1 0.1\nvt 0.9 0.1\nvt 0.9 0.9\nvt 0.1 0.9\n";
  s << "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n";
  s << "o roof\nv 0 " << gap << " 0\nv 0 " << gap << " -1\nv 1 " << gap << " -1\nv 1 " << gap << " 0\nvn 0 -1 0\n";
  s << "vt 1.1 0.1\nvt 1.1 0.9\nvt 1.9 0.9\nvt 1.9 0.1\n";
  s << "f 5/5/2 6/6/2 7/7/2\nf 5/5/2 7/7/2 8/8/2\n";
  return s.str();
}

TEST(BakeFormats, UdimTilesAreBakedIntoOneMapEachAndOccludeEachOther) {
  TempDir dir;
  write_text(dir / "two.obj", two_tile_obj(0.2));
  const RunResult r = run_ao("bake two.obj -s 16 -o 'ao.<UDIM>.png' --json" + kRays, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(fs::exists(dir / "ao.1001.png"));
  ASSERT_TRUE(fs::exists(dir / "ao.1002.png"));
  EXPECT_EQ(dir.file_count(), 3);  // two.obj and the two tiles: no file for empty tiles, none named <UDIM>
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["udim_tiles"].size(), 2u);
  EXPECT_EQ(j["udim_tiles"][0]["tile"], 1001);
  EXPECT_EQ(j["udim_tiles"][1]["tile"], 1002);
  // Each quad covers UVs [0.1, 0.9]^2 of its tile: texels 2..13 of 16 are inside in both maps.
  // A floor 0.2 below a roof of the same size is mostly occluded (the view factor of the roof from
  // the floor's centre is 1 - sin(atan(0.2 / 0.5)) ~ 0.81, so V < 0.5 everywhere under it) and
  // the roof sees the floor the same way: the other tile's triangles occlude.
  for (const char* name : {"ao.1001.png", "ao.1002.png"}) {
    const Image<float> map = read_image(dir / name);
    ASSERT_EQ(map.width(), 16);
    EXPECT_LT(map(8, 8), 0.5f) << name;
    EXPECT_GT(map(8, 8), 0.0f) << name;
  }
  // Apart, each is an open quad (V = 1): the tiles really hold different surfaces.
  write_text(dir / "apart.obj", two_tile_obj(1000.0));
  ASSERT_EQ(run_ao("bake apart.obj -s 16 -o apart.1001.exr" + kRays, dir.path()).exit_code, 0);
  EXPECT_EQ(read_image(dir / "apart.1001.exr")(8, 8), 1.0f);
  EXPECT_EQ(read_image(dir / "apart.1002.exr")(8, 8), 1.0f);
  EXPECT_FALSE(fs::exists(dir / "apart.1003.exr"));
}

TEST(BakeFormats, UdimMisuseIsAOneLineError) {
  TempDir dir;
  write_text(dir / "two.obj", two_tile_obj(0.2));
  expect_one_line_error(run_ao("bake two.obj -o 'ao.<UDIM>.png' --gltf m.glb" + kRays, dir.path()), "--gltf");
  // UVs outside the UDIM range (u < 0).
  write_text(dir / "neg.obj", quad_obj(-0.9, 0.1, -0.1, 0.9));
  expect_one_line_error(run_ao("bake neg.obj -o 'ao.<UDIM>.png'" + kRays, dir.path()), "outside the UDIM tiles");
  EXPECT_EQ(dir.file_count(), 2);
}

}  // namespace
}  // namespace ao::test
