// Mesh loading: counts and positions survive each format, the shared meshes load with the counts
// their headers state, and every family of bad input ends in one InputError line naming the file.
#include "ao/io/mesh_io.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <unistd.h>
#include <utility>
#include <vector>

#include "ao/core/error.h"
#include "support/run.h"

namespace ao {
namespace {

namespace fs = std::filesystem;

using test::TempDir;

/// Loads a file that must be rejected; returns the message after checking that it is one line and
/// names the file.
std::string load_error(const fs::path& path) {
  try {
    load_scene_file(path);
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path.filename().string()), std::string::npos) << "message does not name the file: " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "message is not one line: " << msg;
    return msg;
  }
  ADD_FAILURE() << path << " loaded, expected an InputError";
  return {};
}

#define EXPECT_LOAD_ERROR(path, fragment)                                                         \
  do {                                                                                            \
    const std::string msg_ = load_error(path);                                                    \
    EXPECT_NE(msg_.find(fragment), std::string::npos) << "expected '" << (fragment) << "' in: " << msg_; \
  } while (0)

void expect_near(Vec3 a, Vec3 b) {
  EXPECT_NEAR(a.x, b.x, 1e-6f);
  EXPECT_NEAR(a.y, b.y, 1e-6f);
  EXPECT_NEAR(a.z, b.z, 1e-6f);
}

bool has_warning(const Scene& s, const std::string& fragment) {
  for (const std::string& w : s.warnings)
    if (w.find(fragment) != std::string::npos) return true;
  return false;
}

fs::path shared_meshes() { return AO_SHARED_MESHES; }

std::vector<fs::path> shared_files(const std::string& suffix) {
  std::vector<fs::path> files;
  if (!fs::is_directory(shared_meshes())) return files;
  for (const auto& entry : fs::directory_iterator(shared_meshes())) {
    const std::string name = entry.path().filename().string();
    if (name.size() >= suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// OFF header read independently of the loader: counts, and whether every face is a triangle.
struct OffHeader {
  long long vertices = -1, faces = -1;
  bool all_triangles = true;
};

OffHeader read_off_header(const fs::path& p) {
  // Token by token: the shared files have no comments, but some put a blank line after the counts.
  std::ifstream in(p);
  std::string keyword;
  OffHeader h;
  long long edges = 0;
  in >> keyword >> h.vertices >> h.faces >> edges;
  double coordinate = 0;
  for (long long k = 0; k < 3 * h.vertices; ++k) in >> coordinate;
  for (long long f = 0; f < h.faces && in; ++f) {
    long long n = 0, index = 0;
    in >> n;
    for (long long k = 0; k < n; ++k) in >> index;
    h.all_triangles = h.all_triangles && n == 3;
  }
  h.all_triangles = h.all_triangles && static_cast<bool>(in);
  return h;
}

const char* const kQuadObj =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "f 1/1 2/2 3/3 4/4\n";

// --- the shared meshes -------------------------------------------------------------------------

TEST(MeshIo, OffCountsMatchHeader) {
  const std::vector<fs::path> files = shared_files(".off");
  if (files.empty()) GTEST_SKIP() << "no meshes in " << shared_meshes();
  for (const fs::path& p : files) {
    SCOPED_TRACE(p.string());
    const OffHeader h = read_off_header(p);
    EXPECT_TRUE(h.all_triangles);
    const Scene s = load_scene_file(p);
    ASSERT_EQ(s.meshes.size(), 1u);
    EXPECT_EQ(s.name, p.filename().string());
    EXPECT_EQ(static_cast<long long>(s.vertex_count()), h.vertices);
    // Degenerate triangles are dropped with a warning; without a warning every face must be there.
    if (s.warnings.empty())
      EXPECT_EQ(static_cast<long long>(s.triangle_count()), h.faces);
    else
      EXPECT_LT(static_cast<long long>(s.triangle_count()), h.faces);
    EXPECT_EQ(s.meshes[0].normals.size(), s.meshes[0].positions.size());
    EXPECT_TRUE(s.meshes[0].uvs.empty());
  }
}

TEST(MeshIo, UvObjFilesLoadWithUvsAndNormals) {
  const std::vector<fs::path> files = shared_files("_uv.obj");
  if (files.empty()) GTEST_SKIP() << "no meshes in " << shared_meshes();
  for (const fs::path& p : files) {
    SCOPED_TRACE(p.string());
    std::size_t face_lines = 0;
    std::ifstream in(p);
    for (std::string line; std::getline(in, line);) face_lines += line.starts_with("f ");
    const Scene s = load_scene_file(p);
    ASSERT_FALSE(s.meshes.empty());
    if (s.warnings.empty()) {
      EXPECT_EQ(s.triangle_count(), face_lines) << "every face line there is a triangle";
    }
    for (const Mesh& m : s.meshes) {
      EXPECT_EQ(m.uvs.size(), m.positions.size());
      EXPECT_EQ(m.normals.size(), m.positions.size());
      for (const Vec3& n : m.normals) ASSERT_NEAR(length(n), 1.0f, 1e-4f);
    }
  }
}

// --- each format, written small ---------------------------------------------------------------

TEST(MeshIo, ObjQuadIsTriangulatedWithUvs) {
  TempDir dir;
  const Scene s = load_scene_file(dir.write("quad.obj", kQuadObj));
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.name, "quad.obj");
  EXPECT_EQ(s.triangle_count(), 2u);
  EXPECT_EQ(s.vertex_count(), 4u);
  EXPECT_EQ(s.meshes[0].uvs.size(), 4u);
  for (const Vec3& n : s.meshes[0].normals) expect_near(n, {0, 0, 1});
  const Bounds3 b = s.bounds();
  expect_near(b.lo, {0, 0, 0});
  expect_near(b.hi, {1, 1, 0});
}

TEST(MeshIo, ObjWithoutMaterialGetsDefaultAlbedo) {
  TempDir dir;
  const Scene s = load_scene_file(dir.write("quad.obj", kQuadObj));
  expect_near(s.meshes[0].albedo, Mesh{}.albedo);
}

TEST(MeshIo, ObjMaterialsSplitMeshesAndGiveAlbedo) {
  TempDir dir;
  dir.write("two.mtl", "newmtl red\nKd 0.9 0.1 0.1\nnewmtl blue\nKd 0.1 0.2 0.7\n");
  const Scene s = load_scene_file(dir.write("two.obj",
                                            "mtllib two.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                            "usemtl red\nf 1 2 3\nusemtl blue\nf 1 2 4\n"));
  ASSERT_EQ(s.meshes.size(), 2u);
  std::vector<Vec3> albedos{s.meshes[0].albedo, s.meshes[1].albedo};
  std::sort(albedos.begin(), albedos.end(), [](Vec3 a, Vec3 b) { return a.x < b.x; });
  expect_near(albedos[0], {0.1f, 0.2f, 0.7f});
  expect_near(albedos[1], {0.9f, 0.1f, 0.1f});
}

TEST(MeshIo, OffKeepsVertexOrderAndFansPolygons) {
  TempDir dir;
  const Scene s = load_scene_file(dir.write("quad.off",
                                            "OFF\n# a comment line\n5 1 0\n0 0 0\n1 0 0  # trailing comment\n1 1 0\n0 1 0\n"
                                            "0.5 1.5 0\n5 0 1 2 4 3\n"));
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.vertex_count(), 5u);
  EXPECT_EQ(s.triangle_count(), 3u);
  expect_near(s.meshes[0].positions[1], {1, 0, 0});
  expect_near(s.meshes[0].positions[4], {0.5f, 1.5f, 0});
  const std::vector<std::uint32_t> fan{0, 1, 2, 0, 2, 4, 0, 4, 3};
  EXPECT_EQ(s.meshes[0].indices, fan);
}

TEST(MeshIo, OffCountsOnKeywordLineAndColoursAndNormalsAreRead) {
  TempDir dir;
  const Scene c = load_scene_file(dir.write("c.off", "COFF 3 1 0\n0 0 0 255 0 0 255\n1 0 0 255 0 0 255\n0 1 0 255 0 0 255\n3 0 1 2 1 1 1\n"));
  EXPECT_EQ(c.triangle_count(), 1u);
  const Scene n = load_scene_file(dir.write("n.off", "NOFF\n3 1 0\n0 0 0 0 0 -2\n1 0 0 0 0 -2\n0 1 0 0 0 -2\n3 0 1 2\n"));
  ASSERT_EQ(n.meshes[0].normals.size(), 3u);
  expect_near(n.meshes[0].normals[0], {0, 0, -1});  // the file's normal, made unit, not the generated +z
}

TEST(MeshIo, PlyAsciiRoundTrip) {
  TempDir dir;
  const Scene s = load_scene_file(dir.write("quad.ply",
                                            "ply\nformat ascii 1.0\ncomment tiny\nelement vertex 4\nproperty float x\nproperty float y\n"
                                            "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                            "0 0 0\n2 0 0\n2 3 0\n0 3 0\n4 0 1 2 3\n"));
  EXPECT_EQ(s.triangle_count(), 2u);
  EXPECT_EQ(s.vertex_count(), 4u);
  expect_near(s.bounds().hi, {2, 3, 0});
  expect_near(s.meshes[0].albedo, Mesh{}.albedo);  // PLY has no material: not assimp's white
}

TEST(MeshIo, StlAsciiIsWeldedIntoAConnectedMesh) {
  TempDir dir;
  // Two facets sharing an edge, with facet normals that are deliberately wrong (zero): they are
  // dropped, the shared corners are welded, and smooth normals are generated.
  const Scene s = load_scene_file(dir.write("quad.stl",
                                            "solid q\n"
                                            "facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nendloop\nendfacet\n"
                                            "facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\n"
                                            "endsolid q\n"));
  EXPECT_EQ(s.triangle_count(), 2u);
  EXPECT_EQ(s.vertex_count(), 4u);
  for (const Vec3& n : s.meshes[0].normals) expect_near(n, {0, 0, 1});
}

TEST(MeshIo, GltfEmbeddedBufferAppliesNodeTransformAndBaseColor) {
  TempDir dir;
  // One triangle (0,0,0) (1,0,0) (0,1,0) as float32 VEC3 positions plus uint16 indices, base64:
  // the node moves it by +10 in x and the material's baseColorFactor is (0.2, 0.4, 0.6).
  const std::string gltf = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],
    "nodes":[{"mesh":0,"translation":[10,0,0]}],
    "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,"material":0}]}],
    "materials":[{"pbrMetallicRoughness":{"baseColorFactor":[0.2,0.4,0.6,1]}}],
    "buffers":[{"byteLength":44,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA="}],
    "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":6}],
    "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
                 {"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}]})";
  const Scene s = load_scene_file(dir.write("tri.gltf", gltf));
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.triangle_count(), 1u);
  expect_near(s.bounds().lo, {10, 0, 0});
  expect_near(s.bounds().hi, {11, 1, 0});
  expect_near(s.meshes[0].albedo, {0.2f, 0.4f, 0.6f});
}

// A unit quad (z = 0, facing +z) with two UV sets, as glTF with an embedded base64 buffer:
// TEXCOORD_0 spans [0.1, 0.4]^2 and TEXCOORD_1 [0.5, 0.9]^2 (glTF's v-down convention).
const std::string kTwoUvSetsGltf = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],
  "nodes":[{"mesh":0}],
  "meshes":[{"name":"quad","primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1,"TEXCOORD_1":2},"indices":3}]}],
  "buffers":[{"byteLength":124,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAACAPwAAgD8AAAAAAAAAAAAAgD8AAAAAzczMPc3MzD3NzMw+zczMPc3MzD7NzMw+zczMPc3MzD4AAAA/AAAAP2ZmZj8AAAA/ZmZmP2ZmZj8AAAA/ZmZmPwAAAQACAAAAAgADAA=="}],
  "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":32},
                 {"buffer":0,"byteOffset":80,"byteLength":32},{"buffer":0,"byteOffset":112,"byteLength":12}],
  "accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
               {"bufferView":1,"componentType":5126,"count":4,"type":"VEC2"},
               {"bufferView":2,"componentType":5126,"count":4,"type":"VEC2"},
               {"bufferView":3,"componentType":5123,"count":6,"type":"SCALAR"}]})";

/// UV range of a loaded mesh.
std::pair<Vec2, Vec2> uv_range(const Mesh& m) {
  Vec2 lo{1e9f, 1e9f}, hi{-1e9f, -1e9f};
  for (const Vec2& t : m.uvs) {
    lo = {std::min(lo.x, t.x), std::min(lo.y, t.y)};
    hi = {std::max(hi.x, t.x), std::max(hi.y, t.y)};
  }
  return {lo, hi};
}

TEST(MeshIo, GltfUvSetOptionPicksTheSecondSet) {
  TempDir dir;
  const fs::path file = dir.write("two-sets.gltf", kTwoUvSetsGltf);
  // Default: the first set. The loader turns glTF's v-down into v-up (v' = 1 - v).
  const Scene first = load_scene_file(file);
  ASSERT_EQ(first.meshes.size(), 1u);
  ASSERT_EQ(first.meshes[0].uvs.size(), first.meshes[0].positions.size());
  auto [lo0, hi0] = uv_range(first.meshes[0]);
  EXPECT_NEAR(lo0.x, 0.1f, 1e-6f);
  EXPECT_NEAR(hi0.x, 0.4f, 1e-6f);
  EXPECT_NEAR(lo0.y, 0.6f, 1e-6f);
  EXPECT_NEAR(hi0.y, 0.9f, 1e-6f);
  const Scene second = load_scene_file(file, {.uv_set = 1});
  ASSERT_EQ(second.meshes.size(), 1u);
  ASSERT_EQ(second.meshes[0].uvs.size(), second.meshes[0].positions.size());
  auto [lo1, hi1] = uv_range(second.meshes[0]);
  EXPECT_NEAR(lo1.x, 0.5f, 1e-6f);
  EXPECT_NEAR(hi1.x, 0.9f, 1e-6f);
  EXPECT_NEAR(lo1.y, 0.1f, 1e-6f);
  EXPECT_NEAR(hi1.y, 0.5f, 1e-6f);
  // Same vertices, each with its own UV of the other set: vertex (1,0,0) has TEXCOORD_1 (0.9, 0.5).
  for (std::size_t v = 0; v < second.meshes[0].positions.size(); ++v) {
    const Vec3 p = second.meshes[0].positions[v];
    EXPECT_NEAR(second.meshes[0].uvs[v].x, 0.5f + 0.4f * p.x, 1e-6f) << v;
    EXPECT_NEAR(second.meshes[0].uvs[v].y, 1.0f - (0.5f + 0.4f * p.y), 1e-6f) << v;
  }
}

TEST(MeshIo, AbsentUvSetIsAnInputErrorCountingTheSets) {
  TempDir dir;
  try {
    load_scene_file(dir.write("two-sets.gltf", kTwoUvSetsGltf), {.uv_set = 2});
    ADD_FAILURE() << "loaded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("two-sets.gltf: has 2 UV sets, --uv-set 2 asked for"), std::string::npos) << e.what();
  }
  for (const auto& [name, content, sets] : {std::tuple{"quad.obj", std::string(kQuadObj), "has 1 UV set,"},
                                             std::tuple{"tri.off", std::string("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"), "has 0 UV sets,"}}) {
    try {
      load_scene_file(dir.write(name, content), {.uv_set = 1});
      ADD_FAILURE() << name << " loaded";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(std::string(name) + ": " + sets + " --uv-set 1 asked for"), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }
  // Set 0 of a file without UVs still loads (without UVs), as before.
  EXPECT_TRUE(load_scene_file(dir.write("tri2.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")).meshes[0].uvs.empty());
}

TEST(MeshIo, SomeDegenerateTrianglesLoadWithWarning) {
  TempDir dir;
  const Scene s = load_scene_file(dir.write("some.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n2 0 0\n3 0 1 2\n3 0 1 3\n"));
  EXPECT_EQ(s.triangle_count(), 1u);
  EXPECT_TRUE(has_warning(s, "degenerate")) << "warnings: " << s.warnings.size();
  const Scene o = load_scene_file(dir.write("some.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n"));
  EXPECT_EQ(o.triangle_count(), 1u);
  EXPECT_TRUE(has_warning(o, "degenerate"));
}

// --- bad input --------------------------------------------------------------------------------

TEST(MeshIo, MissingFileIsAnInputError) {
  TempDir dir;
  EXPECT_LOAD_ERROR(dir.path() / "nothere.obj", "no such file");
}

TEST(MeshIo, EmptyFileIsAnInputError) {
  TempDir dir;
  for (const char* name : {"empty.off", "empty.obj", "empty.ply", "empty.stl", "empty.gltf", "empty"})
    EXPECT_LOAD_ERROR(dir.write(name, ""), "empty");
}

TEST(MeshIo, DirectoryIsAnInputError) {
  TempDir dir;
  fs::create_directory(dir.path() / "folder.obj");
  EXPECT_LOAD_ERROR(dir.path() / "folder.obj", "directory");
}

TEST(MeshIo, GarbageBytesAreAnInputErrorInEveryFormat) {
  TempDir dir;
  std::mt19937 rng(12345);
  for (const char* ext : {".off", ".obj", ".ply", ".stl", ".gltf", ".glb", ".bin", ""}) {
    for (int size : {1, 7, 100, 5000}) {
      std::string bytes(static_cast<std::size_t>(size), '\0');
      for (char& c : bytes) c = static_cast<char>(rng() & 0xff);
      load_error(dir.write("garbage" + std::to_string(size) + ext, bytes));
    }
  }
}

TEST(MeshIo, UnknownFormatIsNamed) {
  TempDir dir;
  EXPECT_LOAD_ERROR(dir.write("notes.txt", "hello, this is not a mesh\n"), "format");
}

TEST(MeshIo, TruncatedGltfIsAnInputError) {
  TempDir dir;
  EXPECT_LOAD_ERROR(dir.write("cut.gltf", R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nod)"), "malformed or truncated");
}

TEST(MeshIo, TruncatedOffMidVertexListIsAnInputError) {
  TempDir dir;
  // Long numbers, so that the file is not so short that the header's counts alone give it away.
  const std::string v = "0.000000000 0.000000000 0.000000000\n";
  EXPECT_LOAD_ERROR(dir.write("cut.off", "OFF\n4 2 0\n" + v + v), "truncated: expected 4 vertices, found 2");
  // Cut inside a vertex line: the line has too few numbers.
  EXPECT_LOAD_ERROR(dir.write("cut2.off", "OFF\n4 2 0\n" + v + v + "0.000000000 1.0"), "vertex 2 has 2 numbers");
}

TEST(MeshIo, TruncatedOffMidFaceListIsAnInputError) {
  TempDir dir;
  EXPECT_LOAD_ERROR(dir.write("cut.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n"), "expected 2 faces, found 1");
  EXPECT_LOAD_ERROR(dir.write("cut2.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 1 3"), "face 1 says 3 vertices but lists 2");
}

TEST(MeshIo, TruncatedCopiesOfRealFilesAreRejected) {
  const fs::path cow = shared_meshes() / "cow.off";
  if (!fs::exists(cow)) GTEST_SKIP() << "no " << cow;
  TempDir dir;
  const std::string text = read_text(cow);
  // Every OFF cut is caught, whether it falls in the header, a vertex or a face.
  for (std::size_t cut : {std::size_t{5}, std::size_t{20}, text.size() / 3, text.size() / 2, text.size() - 30})
    load_error(dir.write("cow_cut" + std::to_string(cut) + ".off", text.substr(0, cut)));
}

TEST(MeshIo, TruncatedObjNeverCrashes) {
  const std::vector<fs::path> files = shared_files("_uv.obj");
  if (files.empty()) GTEST_SKIP() << "no meshes in " << shared_meshes();
  TempDir dir;
  const std::string text = read_text(files.front());
  // OBJ states no counts, so a cut at a line end is a valid smaller mesh; a cut mid-line must be
  // either rejected or loaded, never crash.
  for (std::size_t cut : {std::size_t{10}, text.size() / 2, text.size() / 2 + 7, text.size() - 5}) {
    const fs::path p = dir.write("cut" + std::to_string(cut) + ".obj", text.substr(0, cut));
    try {
      const Scene s = load_scene_file(p);
      EXPECT_GT(s.triangle_count(), 0u);
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(p.filename().string()), std::string::npos);
    }
  }
}

TEST(MeshIo, OffIndexOutOfRangeIsAnInputError) {
  TempDir dir;
  EXPECT_LOAD_ERROR(dir.write("big.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9001\n"), "face 0 uses vertex 9001, the file has 3");
  EXPECT_LOAD_ERROR(dir.write("neg.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n"), "uses vertex -1");
}

TEST(MeshIo, OffNonFiniteCoordinateIsAnInputError) {
  TempDir dir;
  for (const char* bad : {"nan", "inf", "-inf", "1e39"})
    EXPECT_LOAD_ERROR(dir.write(std::string("bad_") + bad + ".off", std::string("OFF\n3 1 0\n0 0 0\n1 0 0\n0 ") + bad + " 0\n3 0 1 2\n"),
                      "vertex 2 has a non-finite coordinate");
  EXPECT_LOAD_ERROR(dir.write("word.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 abc 0\n3 0 1 2\n"), "'abc' is not a number");
}

TEST(MeshIo, OffNegativeCountsAreAnInputError) {
  TempDir dir;
  EXPECT_LOAD_ERROR(dir.write("neg.off", "OFF\n-3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"), "negative");
  EXPECT_LOAD_ERROR(dir.write("negf.off", "OFF\n3 -1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"), "negative");
}

TEST(MeshIo, OffEnormousCountsFailFastBeforeAllocating) {
  TempDir dir;
  const auto start = std::chrono::steady_clock::now();
  // 4e8 vertices made assimp allocate 7.8 GB for 60 bytes of file; 9e18 would overflow naive sizes.
  EXPECT_LOAD_ERROR(dir.write("huge.off", "OFF\n400000000 200000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
                    "header says 400000000 vertices and 200000000 faces but the file has only");
  EXPECT_LOAD_ERROR(dir.write("huger.off", "OFF\n9000000000000000000 1 0\n0 0 0\n"), "header says");
  EXPECT_LOAD_ERROR(dir.write("overflow.off", "OFF\n99999999999999999999999 1 0\n0 0 0\n"), "is not a count");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 1.0) << "rejecting absurd counts must not depend on them";
}

TEST(MeshIo, UnsupportedOffVariantsAreNamed) {
  TempDir dir;
  EXPECT_LOAD_ERROR(dir.write("st.off", "STOFF\n3 1 0\n0 0 0 0 0\n1 0 0 1 0\n0 1 0 0 1\n3 0 1 2\n"), "unsupported OFF variant 'STOFF'");
  EXPECT_LOAD_ERROR(dir.write("bin.off", "OFF BINARY\n"), "binary OFF");
  EXPECT_LOAD_ERROR(dir.write("poly.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n"), "at least 3");
}

TEST(MeshIo, ObjIndexOutOfRangeIsAnInputError) {
  TempDir dir;
  EXPECT_LOAD_ERROR(dir.write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 99\n"), "out of range");
}

TEST(MeshIo, ObjNanCoordinateIsAnInputError) {
  TempDir dir;
  // Before JoinIdenticalVertices, which would otherwise merge the NaN vertex into a neighbour.
  EXPECT_LOAD_ERROR(dir.write("nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n"), "vertex 2 has a non-finite coordinate");
  EXPECT_LOAD_ERROR(dir.write("inf.obj", "v 0 0 0\nv 1 0 0\nv inf 1 0\nf 1 2 3\n"), "non-finite");
}

TEST(MeshIo, OnlyDegenerateTrianglesIsAnInputError) {
  TempDir dir;
  EXPECT_LOAD_ERROR(dir.write("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"), "no triangles with nonzero area");
  EXPECT_LOAD_ERROR(dir.write("flat.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n3 0 0 1\n"), "no triangles with nonzero area");
}

TEST(MeshIo, ObjWithOnlyLinesIsAnInputError) {
  TempDir dir;
  EXPECT_LOAD_ERROR(dir.write("lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n"), "no triangles");
}

TEST(MeshIo, PlyCutInsideHeaderFailsInsteadOfHanging) {
  TempDir dir;
  // assimp 5.2.5 loops forever on this file.
  EXPECT_LOAD_ERROR(dir.write("cut.ply",
                              "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                              "element face 1\nproperty li"),
                    "end_header");
}

TEST(MeshIo, PlyEnormousCountsFailFast) {
  TempDir dir;
  EXPECT_LOAD_ERROR(dir.write("huge.ply",
                              "ply\nformat binary_little_endian 1.0\nelement vertex 300000000\nproperty float x\nproperty float y\n"
                              "property float z\nend_header\n0000"),
                    "header declares 300000000 x 'vertex' elements");
}

TEST(MeshIo, PlyAsciiMissingFacesIsTruncated) {
  TempDir dir;
  // assimp loads this with an invented second face.
  EXPECT_LOAD_ERROR(dir.write("short.ply",
                              "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                              "element face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
                    "truncated");
}

TEST(MeshIo, PlyAbsurdListCountsFailFast) {
  TempDir dir;
  const std::string header =
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uint int vertex_indices\nend_header\n";
  // assimp allocates a list of whatever count it reads: 16 GB here.
  EXPECT_LOAD_ERROR(dir.write("ascii.ply", "ply\nformat ascii 1.0\n" + header + "0 0 0\n1 0 0\n0 1 0\n4294967295 0 1 2\n"),
                    "expects 4294967295 more values");
  std::string bin = "ply\nformat binary_little_endian 1.0\n" + header + std::string(36, '\0');
  bin += std::string("\xff\xff\xff\x7f", 4) + std::string(12, '\0');
  EXPECT_LOAD_ERROR(dir.write("binary.ply", bin), "truncated");
}

TEST(MeshIo, PlyBinaryRoundTrip) {
  TempDir dir;
  std::string bin =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::int32_t face[3] = {0, 1, 2};
  bin.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
  bin += '\3';
  bin.append(reinterpret_cast<const char*>(face), sizeof face);
  const Scene s = load_scene_file(dir.write("tri.ply", bin));
  EXPECT_EQ(s.triangle_count(), 1u);
  expect_near(s.bounds().hi, {1, 1, 0});
  // One byte short of the last index.
  load_error(dir.write("short.ply", bin.substr(0, bin.size() - 1)));
}

TEST(MeshIo, PlyIndexOutOfRangeIsAnInputError) {
  TempDir dir;
  load_error(dir.write("bad.ply",
                       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                       "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"));
}

TEST(MeshIo, StlTruncatedIsAnInputError) {
  TempDir dir;
  load_error(dir.write("cut.stl", "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"));
  // Binary STL whose triangle count promises far more data than the file has.
  std::string bin(80, '\0');
  bin += std::string("\x00\xe1\xf5\x05", 4);  // 100,000,000 triangles, little endian
  bin += std::string(50, '\0');
  load_error(dir.write("cut_binary.stl", bin));
}

}  // namespace
}  // namespace ao
