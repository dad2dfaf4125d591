// SPDX-License-Identifier: Apache-2.0
// The fast OBJ reader (obj_reader.h) against the reader it replaces for one-mesh files: assimp 5.2
// with the post-processing load_scene_file gave it (triangulate, join identical vertices, sort by
// primitive type, pre-transform). Same vertices in the same order, same triangles, UVs, normals,
// name and albedo; the files it does not take go the old way with the old messages.
#include <gtest/gtest.h>

#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <string_view>

#include "ao/core/error.h"
#include "ao/io/mesh_io.h"
#include "ao/io/obj_reader.h"
#include "support/load_error.h"
#include "support/run.h"

namespace ao {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

/// What assimp makes of `path` with load_scene_file's former post-processing, as one Mesh (names,
/// attributes, indices), through validate_and_prepare as load_scene_file did.
Mesh assimp_mesh(const fs::path& path) {
  Assimp::Importer importer;
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* s = importer.ReadFile(path.string(), aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType |
                                                          aiProcess_PreTransformVertices);
  EXPECT_NE(s, nullptr) << importer.GetErrorString();
  Mesh m;
  if (s == nullptr || s->mNumMeshes != 1) {
    ADD_FAILURE() << "assimp made " << (s ? s->mNumMeshes : 0) << " meshes";
    return m;
  }
  const aiMesh& in = *s->mMeshes[0];
  m.name = in.mName.C_Str();
  for (unsigned v = 0; v < in.mNumVertices; ++v) {
    m.positions.push_back({in.mVertices[v].x, in.mVertices[v].y, in.mVertices[v].z});
    if (in.HasNormals()) m.normals.push_back({in.mNormals[v].x, in.mNormals[v].y, in.mNormals[v].z});
    if (in.HasTextureCoords(0)) m.uvs.push_back({in.mTextureCoords[0][v].x, in.mTextureCoords[0][v].y});
  }
  for (unsigned f = 0; f < in.mNumFaces; ++f) m.indices.insert(m.indices.end(), in.mFaces[f].mIndices, in.mFaces[f].mIndices + 3);
  aiColor4D c;
  aiString material;
  s->mMaterials[in.mMaterialIndex]->Get(AI_MATKEY_NAME, material);
  if (std::string_view(material.C_Str()) != AI_DEFAULT_MATERIAL_NAME && s->mMaterials[in.mMaterialIndex]->Get(AI_MATKEY_COLOR_DIFFUSE, c) == aiReturn_SUCCESS)
    m.albedo = {c.r, c.g, c.b};
  Scene scene;
  scene.name = "reference";
  scene.meshes.push_back(std::move(m));
  validate_and_prepare(scene);
  return scene.meshes.at(0);
}

/// The fast reader's mesh of `path`, which must take the file.
Mesh fast_mesh(const fs::path& path) {
  const std::string text = test::read_text(path);
  std::optional<Scene> s = read_simple_obj(path, text, {});
  if (!s) {
    ADD_FAILURE() << path << " was not taken by the fast reader";
    return {};
  }
  EXPECT_EQ(s->meshes.size(), 1u);
  return s->meshes.at(0);
}

// Coordinates are written with 6 decimals: both readers round them to float, from_chars
// correctly, assimp's fast_atof sometimes one unit in the last place off (2^-23 relative).
void expect_close(Vec3 a, Vec3 b, const std::string& what) {
  for (int k = 0; k < 3; ++k) {
    const float x = k == 0 ? a.x : k == 1 ? a.y : a.z, y = k == 0 ? b.x : k == 1 ? b.y : b.z;
    ASSERT_LE(std::abs(x - y), 2.4e-7f * std::max(1.0f, std::abs(y))) << what << ": " << x << " against " << y;
  }
}

void expect_same(const Mesh& fast, const Mesh& ref) {
  EXPECT_EQ(fast.name, ref.name);
  ASSERT_EQ(fast.indices.size(), ref.indices.size());
  for (std::size_t i = 0; i < ref.indices.size(); ++i)
    ASSERT_EQ(fast.indices[i], ref.indices[i]) << "triangle " << i / 3 << ": (" << fast.indices[i / 3 * 3] << " " << fast.indices[i / 3 * 3 + 1] << " "
                                               << fast.indices[i / 3 * 3 + 2] << ") against (" << ref.indices[i / 3 * 3] << " "
                                               << ref.indices[i / 3 * 3 + 1] << " " << ref.indices[i / 3 * 3 + 2] << ")";
  ASSERT_EQ(fast.positions.size(), ref.positions.size());
  ASSERT_EQ(fast.uvs.size(), ref.uvs.size());
  ASSERT_EQ(fast.normals.size(), ref.normals.size());
  for (std::size_t v = 0; v < ref.positions.size(); ++v) {
    expect_close(fast.positions[v], ref.positions[v], "position " + std::to_string(v));
    expect_close(fast.normals[v], ref.normals[v], "normal " + std::to_string(v));
    if (!ref.uvs.empty()) expect_close({fast.uvs[v].x, fast.uvs[v].y, 0}, {ref.uvs[v].x, ref.uvs[v].y, 0}, "uv " + std::to_string(v));
  }
  expect_close(fast.albedo, ref.albedo, "albedo");
}

/// A random one-mesh OBJ: `quads` faces of 4 random corners (convex, concave and twisted ones),
/// attributes shared between faces, duplicate vertex lines, negative and forward indices.
std::string random_obj(unsigned seed, const std::string& form, int quads) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1, 1);
  std::ostringstream o;
  o.setf(std::ios::fixed);
  o.precision(6);
  const int nv = quads * 2 + 4;
  o << "o random_" << seed << "\n";
  std::vector<std::string> corners;
  for (int f = 0; f < quads; ++f) {
    const int n = f % 3 == 0 ? 3 : 4;
    std::string line = "f";
    for (int k = 0; k < n; ++k) {
      const int v = static_cast<int>(rng() % nv) + 1, t = static_cast<int>(rng() % nv) + 1, m = static_cast<int>(rng() % 7) + 1;
      // Appended piecewise: "literal" + std::string trips GCC 12's false -Wrestrict.
      line += ' ';
      line += std::to_string(v);
      if (form == "vt" || form == "vtn") line += '/', line += std::to_string(t);
      if (form == "vn") line += "//", line += std::to_string(m);
      if (form == "vtn") line += '/', line += std::to_string(m);
    }
    corners.push_back(line + "\n");
  }
  // Half the faces before the vertices they use (forward references), half after.
  for (std::size_t f = 0; f < corners.size() / 2; ++f) o << corners[f];
  for (int v = 0; v < nv; ++v) {
    if (v % 5 == 4) o << "v 0.250000 -0.500000 0.000000\n";  // the same value on several lines
    else o << "v " << u(rng) << " " << u(rng) << " " << u(rng) * 0.3f << "\n";
    o << "vt " << (u(rng) + 1) / 2 << " " << (u(rng) + 1) / 2 << "\n";
  }
  for (int m = 0; m < 7; ++m) o << "vn " << u(rng) << " " << u(rng) << " " << 1.0f << "\n";
  for (std::size_t f = corners.size() / 2; f < corners.size(); ++f) o << corners[f];
  o << "f -1 -2 -3\n";  // negative indices: the last vertices read
  return form == "v" ? o.str() : o.str().substr(0, o.str().rfind("f -1"));
}

TEST(ObjReader, RandomMeshesMatchAssimpVertexForVertex) {
  TempDir dir;
  for (const std::string form : {"v", "vt", "vn", "vtn"})
    for (unsigned seed = 1; seed <= 3; ++seed) {
      SCOPED_TRACE(form + " seed " + std::to_string(seed));
      const fs::path p = dir.write("r.obj", random_obj(seed, form, 300));
      expect_same(fast_mesh(p), assimp_mesh(p));
    }
}

TEST(ObjReader, ConcaveQuadsAreSplitFromTheirConcaveCorner) {
  TempDir dir;
  // An arrowhead: corner 3 points inwards. Rotating the corner order moves the concave corner.
  for (int r = 0; r < 4; ++r) {
    const Vec3 corners[4] = {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {1.5f, 0.5f, 0}};
    std::string text;
    for (int k = 0; k < 4; ++k) {
      const Vec3 c = corners[(k + r) % 4];
      text += "v " + std::to_string(c.x) + " " + std::to_string(c.y) + " 0\n";
    }
    const fs::path p = dir.write("arrow.obj", text + "f 1 2 3 4\n");
    const Mesh m = fast_mesh(p);
    // The concave corner (file corner (3 - r) mod 4) starts both triangles.
    const std::uint32_t concave = static_cast<std::uint32_t>((3 - r + 4) % 4);
    ASSERT_EQ(m.indices.size(), 6u);
    EXPECT_EQ(m.indices[0], concave);
    EXPECT_EQ(m.indices[3], concave);
    expect_same(m, assimp_mesh(p));
  }
}

TEST(ObjReader, NamesMaterialsAndTheRealMeshesMatchAssimp) {
  TempDir dir;
  dir.write("m.mtl", "newmtl red\nKd 0.9 0.1 0.1\nnewmtl blue\nKd 0.1 0.2 0.7\n");
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -0 1 0\nf 1 2 3\nf 2 4 1\n";
  for (const std::string& head : {std::string(), std::string("o thing\n"), std::string("g group\n"), std::string("mtllib m.mtl\nusemtl blue\n"),
                                  std::string("mtllib m.mtl\ng thing\nusemtl red\n"), std::string("mtllib m.mtl\nusemtl red\no thing\ns 1\n")}) {
    SCOPED_TRACE(head);
    const fs::path p = dir.write("t.obj", head + tri);
    const Mesh fast = fast_mesh(p);
    expect_same(fast, assimp_mesh(p));
    EXPECT_EQ(fast.positions.size(), 3u) << "-0 and 0 are one vertex";
  }
  // The shared UV-mapped meshes, when present (the project does not depend on them).
  std::error_code ec;
  for (const fs::path& p : fs::directory_iterator(AO_SHARED_MESHES, ec))
    if (p.extension() == ".obj") {
      SCOPED_TRACE(p.filename().string());
      expect_same(fast_mesh(p), assimp_mesh(p));
    }
}

TEST(ObjReader, OtherFilesGoTheOldWayWithTheOldMessages) {
  TempDir dir;
  dir.write("m.mtl", "newmtl red\nKd 0.9 0.1 0.1\n");
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\n";
  for (const std::string& text : {v + "g a\nf 1 2 3\ng b\nf 1 2 4\n", v + "mtllib m.mtl\nusemtl red\nf 1 2 3\nusemtl blue\nf 1 2 4\n",
                                   v + "f 1 2 3 4 5\n", v + "l 1 2\nf 1 2 3\n", v + "f 1 2 3\nf 1/1 2/1 4/1\nvt 0 0\n", v + "v 0 0 2 1 0 0\nf 1 2 3\n",
                                   v + "vp 0.5\nf 1 2 3\n", v + "mtllib m.mtl\nusemtl purple\nf 1 2 3\n"}) {
    SCOPED_TRACE(text);
    EXPECT_FALSE(read_simple_obj(dir.write("t.obj", text), text, {}).has_value());
    EXPECT_GT(load_scene_file(dir / "t.obj").triangle_count(), 0u);
  }
  for (const auto& [text, message] : std::vector<std::pair<std::string, std::string>>{
           {v + "f 1 2 9\n", "line 6: vertex index 9 is out of range, the file has 5 vertices"},
           {v + "f 1 2 0\n", "vertex index 0 is out of range, OBJ indices start at 1"},
           {"v 0 0 nan\n" + v + "f 1 2 3\n", "line 1: vertex 0 has a non-finite coordinate ('nan')"},
           {"v 0 0 x\n" + v + "f 1 2 3\n", "line 1: vertex 0: 'x' is not a number"},
           {v + "vt 0 nan\nf 1/1 2/1 3/1\n", "UV 0 is not finite"},
           {v + "f 1 2 3\n", "has 0 UV sets, --uv-set 1 asked for"}}) {
    SCOPED_TRACE(text);
    const fs::path p = dir.write("bad.obj", text);
    try {
      load_scene_file(p, {.uv_set = message.find("uv-set") != std::string::npos ? 1 : 0});
      ADD_FAILURE() << "loaded";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

TEST(ObjReader, MaterialLibrariesOutsideTheFolderAreRefusedOnBothPaths) {
  TempDir dir;
  fs::create_directory(dir / "asset");
  dir.write("outside.mtl", "newmtl red\nKd 0.9 0.1 0.1\n");
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
  for (const char* body : {"usemtl red\nf 1 2 3\n", "g a\nusemtl red\nf 1 2 3\ng b\nf 1 2 4\n"}) {
    const fs::path p = dir.write("asset/m.obj", "mtllib ../outside.mtl\n" + v + std::string(body));
    EXPECT_NE(test::load_error(p).find("material library '../outside.mtl' lies outside the asset's folder"), std::string::npos);
    EXPECT_NO_THROW(load_scene_file(p, {.asset_root = dir.path()}));
  }
}

TEST(ObjReader, ValidLinesAssimpRefusedAreRead) {
  // A comment after data and indented lines are valid OBJ; assimp 5.2 failed on both.
  TempDir dir;
  EXPECT_EQ(load_scene_file(dir.write("c.obj", "v 0 0 0 # origin\n  v 1 0 0\n\tv 0 1 0\nf 1 2 3 # the face\n")).triangle_count(), 1u);
}

}  // namespace
}  // namespace ao
