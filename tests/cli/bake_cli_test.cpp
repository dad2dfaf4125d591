// SPDX-License-Identifier: Apache-2.0
// `ao bake` as users and scripts meet it: outputs, --json, batches, and bad input that gets a
// one-line error naming the file, exit status 1 and no (partial) output (SPEC, "Behaviour on bad
// input"). Meshes are tiny OBJ files written here; maps are 16-32 texels, so each run is quick.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include <nlohmann/json.hpp>

#include "ao/bake/denoise.h"
#include "ao/io/image_io.h"
#include "ao/io/mesh_io.h"
#include "support/run.h"

namespace ao::test {
namespace {

namespace fs = std::filesystem;

// Small, quick bakes with each method (options of one method are errors with the other).
const std::string kQuick = " -m histogram --size 16 --directions 32 --pixels-per-texel 4 --padding 2 ";
const std::string kQuickRays = " -m raytraced --size 16 --samples 8 --padding 2 ";

// Unit cube [0,1]^3 as an OBJ with flat normals; with `uvs`, each face gets its own cell of a
// 3 x 2 grid of the UV square (inset, so charts do not touch). Convex: V = 1 everywhere.
std::string cube_obj(bool uvs) {
  const char* v = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";
  const char* vn = "vn 0 0 -1\nvn 0 0 1\nvn 0 -1 0\nvn 0 1 0\nvn -1 0 0\nvn 1 0 0\n";
  const int faces[6][4] = {{1, 4, 3, 2}, {5, 6, 7, 8}, {1, 2, 6, 5}, {4, 8, 7, 3}, {1, 5, 8, 4}, {2, 3, 7, 6}};
  std::ostringstream s;
  s << "# cube written by bake_cli_test\n" << v << vn;
  if (uvs)
    for (int f = 0; f < 6; ++f) {
      const double u0 = (f % 3) / 3.0 + 0.02, u1 = (f % 3 + 1) / 3.0 - 0.02, v0 = (f / 3) / 2.0 + 0.02, v1 = (f / 3 + 1) / 2.0 - 0.02;
      s << "vt " << u0 << " " << v0 << "\nvt " << u1 << " " << v0 << "\nvt " << u1 << " " << v1 << "\nvt " << u0 << " " << v1 << "\n";
    }
  for (int f = 0; f < 6; ++f) {
    s << "f";
    for (int k = 0; k < 4; ++k) {
      s << " " << faces[f][k];
      if (uvs) s << "/" << 4 * f + k + 1 << "/" << f + 1;
      else s << "//" << f + 1;
    }
    s << "\n";
  }
  return s.str();
}

// Index out of range: the loader rejects it.
const std::string kBrokenObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 9/3\n";

// One line on stderr, starting "ao: error:", that mentions `needle`.

TEST(BakeCli, HistogramBakeWritesMapAndJsonSummary) {
  TempDir dir;
  write_text(dir / "cube.obj", cube_obj(true));
  const RunResult r = run_ao("bake cube.obj -o ao.png --json" + kQuick, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image<float> map = read_image(dir / "ao.png");
  EXPECT_EQ(map.width(), 16);
  EXPECT_EQ(map.height(), 16);
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["input"], "cube.obj");
  EXPECT_EQ(j["output"], "ao.png");
  EXPECT_EQ(j["method"], "histogram");
  EXPECT_EQ(j["size"], 16);
  EXPECT_EQ(j["triangles"], 12);
  EXPECT_EQ(j["directions"], 32);
  EXPECT_EQ(j["parameters"]["directions"], 32);
  EXPECT_EQ(j["parameters"]["normalization"], "area");
  EXPECT_GT(j["texels_covered"].get<int>(), 100);
  EXPECT_LE(j["texels_covered"].get<int>(), 256);
  // A convex cube is open everywhere: V ~ 1 up to the histogram's noise and clamping (measured
  // 0.984 at 32 directions and 4 pixels per texel; 0.91 at 1 pixel per texel, where most of these
  // partly covered texels get a handful of pixels per direction).
  EXPECT_GT(j["mean_visibility"].get<double>(), 0.95);
  EXPECT_LE(j["mean_visibility"].get<double>(), 1.0);
  EXPECT_EQ(j["overlapping_texels"], 0);
  EXPECT_EQ(j["degenerate_uv_triangles"], 0);
  for (const char* t : {"load_ms", "uv_coverage_ms", "bake_ms", "padding_ms", "write_ms"}) EXPECT_TRUE(j["timings"].contains(t)) << t;
  // Texels far from every chart (the padding is 2) stay black; the charts are bright.
  EXPECT_GT(map(8, 4), 0.9f);
}

TEST(BakeCli, RaytracedBakeWritesExrWithExactValuesOnAConvexMesh) {
  TempDir dir;
  write_text(dir / "cube.obj", cube_obj(true));
  const RunResult r = run_ao("bake cube.obj -o ao.exr --json" + kQuickRays, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["method"], "raytraced");
  EXPECT_EQ(j["mean_visibility"].get<double>(), 1.0);
  EXPECT_EQ(j["rays"].get<std::uint64_t>(), j["texels_covered"].get<std::uint64_t>() * 8);
  EXPECT_EQ(j["parameters"]["samples"], 8);
  EXPECT_TRUE(j["parameters"]["max_distance"].is_null()) << "unlimited";
  EXPECT_EQ(j["parameters"]["denoise"].get<float>(), kDefaultBakeDenoise);  // maps are filtered by default; all-1 stays exactly 1
  EXPECT_EQ(read_image(dir / "ao.exr").width(), 16);
}

TEST(BakeCli, WithoutOutputNamesTheMapAfterTheMesh) {
  TempDir dir;
  write_text(dir / "cube.obj", cube_obj(true));
  const RunResult r = run_ao("bake cube.obj" + kQuick, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "cube-ao.png"));
  EXPECT_NE(r.err.find("wrote cube-ao.png"), std::string::npos) << r.err;
}

TEST(BakeCli, MeshWithoutUvsIsAnErrorThatSuggestsPerVertex) {
  TempDir dir;
  write_text(dir / "nouv.obj", cube_obj(false));
  const RunResult r = run_ao("bake nouv.obj -o ao.png" + kQuick, dir.path());
  EXPECT_EQ(r.exit_code, 1);
  expect_one_line_error(r, "nouv.obj");
  EXPECT_NE(r.err.find("--per-vertex"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "ao.png"));
  // And what it suggests works.
  const RunResult pv = run_ao("bake nouv.obj --per-vertex v.ply --samples 16", dir.path());
  EXPECT_EQ(pv.exit_code, 0) << pv.err;
  EXPECT_TRUE(fs::exists(dir / "v.ply"));
  EXPECT_FALSE(fs::exists(dir / "nouv-ao.png"));
}

TEST(BakeCli, BatchBakesTheGoodMeshesAndNamesTheBrokenOne) {
  TempDir dir;
  fs::create_directories(dir / "meshes");  // out/ is created by --out-dir
  write_text(dir / "meshes/a.obj", cube_obj(true));
  write_text(dir / "meshes/b_broken.obj", kBrokenObj);
  write_text(dir / "meshes/c.obj", cube_obj(true));
  write_text(dir / "meshes/notes.txt", "not a mesh\n");
  const RunResult r = run_ao("bake meshes --out-dir out --json" + kQuick, dir.path());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_TRUE(fs::exists(dir / "out/a-ao.png"));
  EXPECT_TRUE(fs::exists(dir / "out/c-ao.png"));
  EXPECT_FALSE(fs::exists(dir / "out/b_broken-ao.png"));
  EXPECT_NE(r.err.find("ao: error: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("b_broken.obj"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("error: meshes/a.obj"), std::string::npos) << "only the broken mesh is an error: " << r.err;
  // stderr is not a terminal here: one line as each mesh starts and one as it ends.
  EXPECT_NE(r.err.find("mesh 1 of 3: a.obj ...\n"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("mesh 1 of 3: a.obj ... done in "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("mesh 2 of 3: b_broken.obj ... failed in "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("mesh 3 of 3: c.obj ... done in "), std::string::npos) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.size(), 3u);  // notes.txt is not a mesh file: skipped
  EXPECT_FALSE(j[0].contains("error"));
  EXPECT_TRUE(j[1].contains("error"));
  EXPECT_FALSE(j[2].contains("error"));
  // A list of files works the same, outputs named <stem>-<given name> beside each mesh.
  const RunResult list = run_ao("bake meshes/a.obj meshes/b_broken.obj meshes/c.obj -o map.png" + kQuick, dir.path());
  EXPECT_EQ(list.exit_code, 1);
  EXPECT_TRUE(fs::exists(dir / "meshes/a-map.png"));
  EXPECT_TRUE(fs::exists(dir / "meshes/c-map.png"));
  EXPECT_FALSE(fs::exists(dir / "meshes/b_broken-map.png"));
}

TEST(BakeCli, UnknownExtensionsAreRejectedBeforeBaking) {
  TempDir dir;
  write_text(dir / "cube.obj", cube_obj(true));
  // The mesh reader goes by content (an OBJ named .xyz is read as OBJ), so an unknown input is one
  // whose content no reader recognises.
  write_text(dir / "notes.xyz", "these are not the vertices you are looking for\n");
  const RunResult in = run_ao("bake notes.xyz -o ao.png" + kQuick, dir.path());
  EXPECT_EQ(in.exit_code, 1);
  expect_one_line_error(in, "notes.xyz");
  EXPECT_FALSE(fs::exists(dir / "ao.png"));
  const RunResult out = run_ao("bake cube.obj -o ao.bmp" + kQuick, dir.path());
  EXPECT_EQ(out.exit_code, 1);
  expect_one_line_error(out, "ao.bmp");
  EXPECT_FALSE(fs::exists(dir / "ao.bmp"));
  const RunResult glb = run_ao("bake cube.obj -o ao.png --gltf m.gltf" + kQuick, dir.path());
  EXPECT_EQ(glb.exit_code, 1);
  expect_one_line_error(glb, "m.gltf");
  EXPECT_FALSE(fs::exists(dir / "ao.png"));
  const RunResult ply = run_ao("bake cube.obj -o ao.png --per-vertex v.obj" + kQuick, dir.path());
  EXPECT_EQ(ply.exit_code, 1);
  expect_one_line_error(ply, "v.obj");
  EXPECT_FALSE(fs::exists(dir / "ao.png"));
}

TEST(BakeCli, ExistingOutputIsUntouchedAfterAFailure) {
  TempDir dir;
  write_text(dir / "cube.obj", cube_obj(true));
  write_text(dir / "nouv.obj", cube_obj(false));
  write_text(dir / "ao.png", "previous map");
  write_text(dir / "m.glb", "previous glb");
  // The mesh cannot be baked.
  RunResult r = run_ao("bake nouv.obj -o ao.png --gltf m.glb" + kQuick, dir.path());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(read_text(dir / "ao.png"), "previous map");
  EXPECT_EQ(read_text(dir / "m.glb"), "previous glb");
  // One of the outputs cannot be written (its folder does not exist): nothing is written.
  r = run_ao("bake cube.obj -o ao.png --gltf m.glb --per-vertex nowhere/v.ply" + kQuick, dir.path());
  EXPECT_EQ(r.exit_code, 1);
  expect_one_line_error(r, "nowhere");
  EXPECT_EQ(read_text(dir / "ao.png"), "previous map");
  EXPECT_EQ(read_text(dir / "m.glb"), "previous glb");
  // A bad option value.
  r = run_ao("bake cube.obj -o ao.png --directions 0", dir.path());
  EXPECT_EQ(r.exit_code, 1);
  expect_one_line_error(r, "directions");
  EXPECT_EQ(read_text(dir / "ao.png"), "previous map");
  // No leftover temporary files.
  for (const auto& e : fs::directory_iterator(dir.path())) EXPECT_NE(e.path().filename().string().rfind('.', 0), 0u) << e.path();
}

TEST(BakeCli, PerVertexAndGltfOutputsAreWrittenAndReadable) {
  TempDir dir;
  write_text(dir / "cube.obj", cube_obj(true));
  for (const char* method : {"histogram", "raytraced"}) {
    const std::string m(method);
    const RunResult r = run_ao("bake cube.obj -o ao-" + m + ".exr --per-vertex v-" + m + ".ply --gltf m-" + m + ".glb --json" +
                                   (m == "histogram" ? kQuick + " --vertex-resolution 64" : kQuickRays),
                               dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["per_vertex_output"], "v-" + m + ".ply");
    EXPECT_TRUE(j["timings"].contains("per_vertex_ms"));
    const Scene ply = load_scene_file(dir / ("v-" + m + ".ply"));
    EXPECT_EQ(ply.triangle_count(), 12u);
    EXPECT_EQ(read_text(dir / ("v-" + m + ".ply")).rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
    const Scene glb = load_scene_file(dir / ("m-" + m + ".glb"));
    EXPECT_EQ(glb.triangle_count(), 12u);
    EXPECT_EQ(read_text(dir / ("m-" + m + ".glb")).substr(0, 4), "glTF");
  }
}

// A unit quad with two UV sets (TEXCOORD_0 over [0.1, 0.4]^2, TEXCOORD_1 over [0.5, 0.9]^2, glTF's
// v down) and a named material, as glTF with an embedded base64 buffer.
const std::string kTwoUvSetsGltf = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],
  "nodes":[{"mesh":0}],
  "meshes":[{"name":"quad","primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1,"TEXCOORD_1":2},"indices":3,"material":0}]}],
  "materials":[{"name":"Keep me","pbrMetallicRoughness":{"baseColorFactor":[0.2,0.4,0.6,1],"roughnessFactor":0.5},"doubleSided":true}],
  "buffers":[{"byteLength":124,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAACAPwAAgD8AAAAAAAAAAAAAgD8AAAAAzczMPc3MzD3NzMw+zczMPc3MzD7NzMw+zczMPc3MzD4AAAA/AAAAP2ZmZj8AAAA/ZmZmP2ZmZj8AAAA/ZmZmPwAAAQACAAAAAgADAA=="}],
  "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":32},
                 {"buffer":0,"byteOffset":80,"byteLength":32},{"buffer":0,"byteOffset":112,"byteLength":12}],
  "accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
               {"bufferView":1,"componentType":5126,"count":4,"type":"VEC2"},
               {"bufferView":2,"componentType":5126,"count":4,"type":"VEC2"},
               {"bufferView":3,"componentType":5123,"count":6,"type":"SCALAR"}]})";

TEST(BakeCli, UvSetPicksTheSecondSetAndTheGlbKeepsTheMaterial) {
  TempDir dir;
  write_text(dir / "quad.gltf", kTwoUvSetsGltf);
  // Set 1 covers [0.5, 0.9] x [0.1, 0.5] (v up) = 6.4 x 6.4 texels of a 16^2 map; set 0 the same area elsewhere.
  const RunResult r = run_ao("bake quad.gltf --uv-set 1 -o ao.png --gltf out.glb --json" + kQuick, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["texels_covered"].get<int>(), 30);
  EXPECT_LT(j["texels_covered"].get<int>(), 70);
  // The .glb keeps both sets (the glTF round trip); TEXCOORD_1 is the baked one (read back by the
  // loader in its v-up convention) and the occlusion texture's texCoord.
  const Scene glb = load_scene_file(dir / "out.glb", {.uv_set = 1});
  ASSERT_EQ(glb.meshes.size(), 1u);
  ASSERT_EQ(glb.meshes[0].uvs.size(), 4u);
  for (const Vec2& t : glb.meshes[0].uvs) {
    EXPECT_NEAR(std::min(std::abs(t.x - 0.5f), std::abs(t.x - 0.9f)), 0.0f, 1e-6f) << t.x;
    EXPECT_NEAR(std::min(std::abs(t.y - 0.1f), std::abs(t.y - 0.5f)), 0.0f, 1e-6f) << t.y;
  }
  // The input's material is kept (name, doubleSided) with the occlusion texture added.
  const std::string bytes = read_text(dir / "out.glb");
  EXPECT_NE(bytes.find("\"name\":\"Keep me\""), std::string::npos);
  EXPECT_NE(bytes.find("\"doubleSided\":true"), std::string::npos);
  EXPECT_NE(bytes.find("\"occlusionTexture\":{\"index\":0,\"texCoord\":1}"), std::string::npos);
}

TEST(BakeCli, AbsentUvSetIsAOneLineErrorAndWritesNothing) {
  TempDir dir;
  write_text(dir / "quad.gltf", kTwoUvSetsGltf);
  const RunResult r = run_ao("bake quad.gltf --uv-set 2 -o ao.png --gltf out.glb" + kQuick, dir.path());
  EXPECT_EQ(r.exit_code, 1);
  expect_one_line_error(r, "quad.gltf: has 2 UV sets, --uv-set 2 asked for");
  EXPECT_FALSE(fs::exists(dir / "ao.png"));
  EXPECT_FALSE(fs::exists(dir / "out.glb"));
}

}  // namespace
}  // namespace ao::test

namespace ao::test {
namespace {

// The cube of cube_obj without UVs and with only the faces listed (1-based, cube_obj's order).
std::string cube_faces_obj(std::initializer_list<int> faces) {
  const std::string full = cube_obj(false);
  std::istringstream in(full);
  std::ostringstream out;
  std::string line;
  int face = 0;
  while (std::getline(in, line)) {
    if (line.rfind("f ", 0) == 0) {
      ++face;
      if (std::find(faces.begin(), faces.end(), face) == faces.end()) continue;
    }
    out << line << "\n";
  }
  return out.str();
}

TEST(BakeCliHighToLow, ConvexHighMeshBakesOpenWithNoMisses) {
  TempDir dir;
  write_text(dir / "low.obj", cube_obj(true));
  write_text(dir / "high.obj", cube_obj(false));
  const RunResult r = run_ao("bake low.obj --high high.obj --cage-extrusion 0.05 -o ao.exr --miss-mask miss.png --json --size 16 --samples 8 --padding 2",
                             dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["method"], "raytraced");
  EXPECT_EQ(j["missed_texels"], 0);
  EXPECT_EQ(j["mean_visibility"].get<double>(), 1.0);
  EXPECT_EQ(j["high_triangles"], 12);
  const Image<float> miss = read_image(dir / "miss.png");
  for (std::size_t i = 0; i < miss.size(); ++i) ASSERT_EQ(miss[i], 0.0f);
  // Filtered (high to low is filtered by default too): an open map stays exactly 1.
  const RunResult f = run_ao("bake low.obj --high high.obj --cage-extrusion 0.05 -o ao.exr --json --size 16 --samples 8 --denoise 1", dir.path());
  ASSERT_EQ(f.exit_code, 0) << f.err;
  EXPECT_EQ(nlohmann::json::parse(f.out)["mean_visibility"].get<double>(), 1.0);
}

TEST(BakeCliHighToLow, MissesAreCountedMaskedWarnedAndNotBlack) {
  TempDir dir;
  write_text(dir / "low.obj", cube_obj(true));
  write_text(dir / "high.obj", cube_faces_obj({1, 2, 3}));  // three faces of the cube: the other three miss
  const RunResult r = run_ao("bake low.obj --high high.obj --cage-extrusion 0.05 -o ao.exr --miss-mask miss.png --json --size 16 --samples 8 --padding 2",
                             dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const int missed = j["missed_texels"];
  const int covered = j["texels_covered"];
  // Three of six equal charts miss: about half the covered texels (texels where charts' borders meet
  // are shared in the 16^2 map, hence the slack).
  EXPECT_GT(missed, covered / 3);
  EXPECT_LT(missed, 2 * covered / 3);
  EXPECT_NE(r.err.find("missed the high mesh"), std::string::npos) << r.err;
  const Image<float> miss = read_image(dir / "miss.png");
  const Image<float> map = read_image(dir / "ao.exr");
  int marked = 0;
  for (std::size_t i = 0; i < miss.size(); ++i)
    if (miss[i] > 0.5f) {
      ++marked;
      EXPECT_GT(map[i], 0.5f) << "texel " << i;  // filled from a neighbour that hit (an open face), not black
    }
  EXPECT_EQ(marked, missed);
}

TEST(BakeCliHighToLow, OptionsThatDoNotApplyAreOneLineErrors) {
  TempDir dir;
  write_text(dir / "low.obj", cube_obj(true));
  write_text(dir / "high.obj", cube_obj(false));
  write_text(dir / "half.obj", cube_faces_obj({1, 2, 3}));
  expect_one_line_error(run_ao("bake low.obj --high high.obj -m histogram --size 16", dir.path()), "--high needs --method raytraced");
  expect_one_line_error(run_ao("bake low.obj --cage-extrusion 0.1" + kQuickRays, dir.path()), "need --high");
  expect_one_line_error(run_ao("bake low.obj --high high.obj --cage half.obj" + kQuickRays, dir.path()), "topology");
  expect_one_line_error(run_ao("bake low.obj --high high.obj --cage-extrusion -1" + kQuickRays, dir.path()), "cage_extrusion must be null or a number in [0, 1000000000]");
  EXPECT_FALSE(fs::exists(dir / "low-ao.png"));
}

}  // namespace
}  // namespace ao::test

namespace ao::test {
namespace {

TEST(BakeCli, OptionsOfTheOtherMethodAreOneLineErrors) {
  TempDir dir;
  write_text(dir / "cube.obj", cube_obj(true));
  for (const char* opt : {"--ignore-back-faces", "--membership linear", "--offset 0.01", "--samples 4", "--normal geometric", "--denoise 1"})
    expect_one_line_error(run_ao("bake cube.obj -m histogram --size 16 " + std::string(opt), dir.path()), "does not apply to --method histogram");
  for (const char* opt : {"--directions 8", "--pixels-per-texel 2", "--no-seam-fix", "--normalization max"})
    expect_one_line_error(run_ao("bake cube.obj -m raytraced --size 16 " + std::string(opt), dir.path()), "does not apply to --method raytraced");
  expect_one_line_error(run_ao("bake cube.obj --size 16 --normal face", dir.path()), "normal must be one of shading, geometric, got \"face\"");
  expect_one_line_error(run_ao("bake cube.obj --size 16 --denoise 5", dir.path()), "denoise must be a number in [0, 4] (texels), got 5");
  expect_one_line_error(run_ao("bake cube.obj --size 16 --denoise 1 --per-vertex v.ply", dir.path()), "per-vertex AO is not filtered");
  EXPECT_FALSE(fs::exists(dir / "cube-ao.png"));
}

}  // namespace
}  // namespace ao::test

namespace ao::test {
namespace {

TEST(BakeCli, FloorDarkensTheBaseAndOccludersAreNotBaked) {
  TempDir dir;
  write_text(dir / "cube.obj", cube_obj(true));
  const std::string args = " -o ao.exr --json -m raytraced --size 32 --samples 16 --padding 0";
  const RunResult open = run_ao("bake cube.obj" + args, dir.path());
  const RunResult floor = run_ao("bake cube.obj --floor" + args + " --per-vertex v.ply", dir.path());
  ASSERT_EQ(open.exit_code, 0) << open.err;
  ASSERT_EQ(floor.exit_code, 0) << floor.err;
  EXPECT_EQ(nlohmann::json::parse(open.out)["mean_visibility"].get<double>(), 1.0);
  // The bottom face (1/6 of the charts) is black on the floor, the four sides are half open: the
  // mean is about (4 x 0.5 + 1) / 6 = 0.5.
  EXPECT_NEAR(nlohmann::json::parse(floor.out)["mean_visibility"].get<double>(), 0.5, 0.05);
  // The per-vertex output has the cube's vertices only, not the floor's.
  EXPECT_EQ(load_scene_file(dir / "v.ply").vertex_count(), load_scene_file(dir / "cube.obj").vertex_count());
}

}  // namespace
}  // namespace ao::test

namespace ao::test {
namespace {

TEST(BakeCli, OnlyTheOutputsAskedForAreWritten) {
  TempDir dir;
  write_text(dir / "cube.obj", cube_obj(true));
  ASSERT_EQ(run_ao("bake cube.obj --gltf m.glb" + kQuickRays, dir.path()).exit_code, 0);
  ASSERT_EQ(run_ao("bake cube.obj --bent-normals bent.png" + kQuickRays, dir.path()).exit_code, 0);
  EXPECT_TRUE(fs::exists(dir / "m.glb"));
  EXPECT_TRUE(fs::exists(dir / "bent.png"));
  EXPECT_FALSE(fs::exists(dir / "cube-ao.png"));  // no map beside the input that nobody asked for
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir.path())) files += e.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, 3u);  // cube.obj, m.glb, bent.png
}

TEST(BakeCli, GlbEmbedsA16BitPngWhenAsked) {
  TempDir dir;
  write_text(dir / "cube.obj", cube_obj(true));
  ASSERT_EQ(run_ao("bake cube.obj --gltf m.glb --png-bits 16" + kQuickRays, dir.path()).exit_code, 0);
  const std::string glb = read_text(dir / "m.glb");
  const std::size_t png = glb.find("\x89PNG\r\n\x1a\n");
  ASSERT_NE(png, std::string::npos);
  // IHDR follows the 8-byte signature: length (4), "IHDR" (4), width (4), height (4), bit depth (1).
  EXPECT_EQ(static_cast<int>(static_cast<unsigned char>(glb[png + 24])), 16);
}

}  // namespace
}  // namespace ao::test

namespace ao::test {
namespace {

TEST(BakeCli, PerVertexAoAsGlbColor0) {
  TempDir dir;
  write_text(dir / "nouv.obj", cube_obj(false));
  const RunResult r = run_ao("bake nouv.obj --per-vertex v.glb --samples 8", dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string glb = read_text(dir / "v.glb");
  ASSERT_EQ(glb.substr(0, 4), "glTF");
  EXPECT_NE(glb.find("\"COLOR_0\""), std::string::npos);
  EXPECT_EQ(load_scene_file(dir / "v.glb").triangle_count(), 12u);
  EXPECT_FALSE(fs::exists(dir / "nouv-ao.png"));
}

}  // namespace
}  // namespace ao::test
