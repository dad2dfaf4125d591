// SPDX-License-Identifier: Apache-2.0
// GltfDocument (gltf_document.h): node transforms, primitive modes and accessor encodings read into
// world scenes with known answers; what passes through a save untouched; files outside the input's
// folder never read; bad documents refused with one line.
#include <gtest/gtest.h>

#include <cmath>

#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/io/gltf_document.h"
#include "ao/version.h"
#include "support/gltf_docs.h"
#include "support/run.h"

namespace ao::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// One triangle (0,0,0) (1,0,0) (0,1,0) facing +z, with normals +z, under `node`.
std::string triangle_glb(const json& node, const json& mode_and_extra = json::object()) {
  GltfBuilder b;
  const int pos = b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", true);
  const int nor = b.floats({0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3");
  json prim = {{"attributes", {{"POSITION", pos}, {"NORMAL", nor}}}};
  prim.update(mode_and_extra);
  b.doc["meshes"] = {{{"name", "Tri"}, {"primitives", {prim}}}};
  json n = node;
  n["mesh"] = 0;
  b.doc["nodes"] = {n};
  b.doc["scenes"] = {{{"nodes", {0}}}};
  return b.glb();
}

Vec3 at(const Mesh& m, std::size_t i) { return m.positions[i]; }

void expect_near(Vec3 a, Vec3 b, float tol = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

TEST(GltfDocument, TranslationRotationScaleApplyInTheSpecsOrder) {
  TempDir dir;
  // T * R * S: scale 2, then 90 degrees about +y (x -> -z, z -> x), then move by (1, 2, 3).
  const double s = std::sqrt(0.5);
  write_text(dir / "trs.glb", triangle_glb({{"translation", {1, 2, 3}}, {"rotation", {0, s, 0, s}}, {"scale", {2, 2, 2}}}));
  const GltfDocument doc(dir / "trs.glb", 0);
  const GltfWorldScene w = doc.world_scene(-1);
  ASSERT_EQ(w.scene.meshes.size(), 1u);
  const Mesh& m = w.scene.meshes[0];
  expect_near(at(m, 0), {1, 2, 3});
  expect_near(at(m, 1), {1, 2, 1});  // (1,0,0) * 2 -> (2,0,0) -> (0,0,-2) -> +T
  expect_near(at(m, 2), {1, 4, 3});
  expect_near(m.normals[0], {1, 0, 0});  // +z rotated to +x
}

TEST(GltfDocument, MirroringTransformKeepsTrianglesFacingTheirNormals) {
  TempDir dir;
  write_text(dir / "mirror.glb", triangle_glb({{"scale", {-1, 1, 1}}}));
  const GltfWorldScene w = GltfDocument(dir / "mirror.glb", 0).world_scene(-1);
  const Mesh& m = w.scene.meshes[0];
  const Vec3 face = cross(at(m, m.indices[1]) - at(m, m.indices[0]), at(m, m.indices[2]) - at(m, m.indices[0]));
  EXPECT_GT(dot(face, m.normals[0]), 0.0f);
  EXPECT_GT(m.normals[0].z, 0.99f);  // mirroring x leaves a +z normal as it was
}

TEST(GltfDocument, ParentMatrixAndChildTransformCompose) {
  GltfBuilder b;
  TempDir dir;
  const int pos = b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", true);
  b.doc["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", pos}}}}}}}};
  // Parent: a column-major matrix scaling by 3; child: translation (1, 0, 0), then the mesh.
  b.doc["nodes"] = {{{"matrix", {3, 0, 0, 0, 0, 3, 0, 0, 0, 0, 3, 0, 0, 0, 0, 1}}, {"children", {1}}}, {{"translation", {1, 0, 0}}, {"mesh", 0}}};
  b.doc["scenes"] = {{{"nodes", {0}}}};
  write_text(dir / "nest.glb", b.glb());
  const GltfWorldScene w = GltfDocument(dir / "nest.glb", 0).world_scene(-1);
  const Mesh& m = w.scene.meshes.at(0);
  expect_near(at(m, 0), {3, 0, 0});
  expect_near(at(m, 1), {6, 0, 0});
  expect_near(at(m, 2), {3, 3, 0});
}

TEST(GltfDocument, StripsAndFansBecomeTrianglesFacingTheSameWay) {
  for (int mode : {5, 6}) {
    GltfBuilder b;
    TempDir dir;
    // A unit quad in z = 0 seen from +z: strip order 0 1 3 2 of the corners (0,0) (1,0) (1,1) (0,1) is
    // (0,0) (1,0) (0,1) (1,1); fan order is the corners counter-clockwise.
    const std::vector<float> strip = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}, fan = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    const int pos = b.floats(mode == 5 ? strip : fan, "VEC3", true);
    b.doc["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", pos}}}, {"mode", mode}}}}}};
    b.doc["nodes"] = {{{"mesh", 0}}};
    b.doc["scenes"] = {{{"nodes", {0}}}};
    write_text(dir / "q.glb", b.glb());
    const GltfWorldScene w = GltfDocument(dir / "q.glb", 0).world_scene(-1);
    const Mesh& m = w.scene.meshes.at(0);
    ASSERT_EQ(m.triangle_count(), 2u) << "mode " << mode;
    for (std::size_t t = 0; t < 2; ++t) {
      const Vec3 a = at(m, m.indices[3 * t]), c = cross(at(m, m.indices[3 * t + 1]) - a, at(m, m.indices[3 * t + 2]) - a);
      EXPECT_NEAR(c.z, 1.0f, 1e-6f) << "mode " << mode << " triangle " << t;  // area 1/2, facing +z
    }
  }
}

TEST(GltfDocument, NormalizedAndSparseUvsAreRead) {
  GltfBuilder b;
  TempDir dir;
  const int pos = b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", true);
  // TEXCOORD_0 as normalized unsigned shorts (0, 32768, 65535), then a sparse override of vertex 2.
  const std::uint16_t uv[6] = {0, 0, 65535, 0, 0, 65535};
  const std::uint16_t sparse_index[2] = {2, 0};
  const float sparse_value[2] = {0.25f, 0.5f};
  std::string& bin = b.bin;
  auto view = [&](const void* p, std::size_t n) {
    while (bin.size() % 4) bin.push_back('\0');
    b.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", n}});
    bin.append(static_cast<const char*>(p), n);
    return static_cast<int>(b.doc["bufferViews"].size() - 1);
  };
  const int uv_view = view(uv, sizeof uv), idx_view = view(sparse_index, 2), val_view = view(sparse_value, sizeof sparse_value);
  b.doc["accessors"].push_back({{"bufferView", uv_view}, {"componentType", 5123}, {"normalized", true}, {"count", 3}, {"type", "VEC2"}});
  b.doc["accessors"].push_back({{"bufferView", uv_view},
                                {"componentType", 5126},
                                {"count", 3},
                                {"type", "VEC2"},
                                {"sparse", {{"count", 1}, {"indices", {{"bufferView", idx_view}, {"componentType", 5123}}}, {"values", {{"bufferView", val_view}}}}}});
  // Accessor 2 reuses the ushort view as floats only for its sparse part: give it no bufferView.
  b.doc["accessors"][2].erase("bufferView");
  b.doc["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", 1}, {"TEXCOORD_1", 2}}}}}}}};
  b.doc["nodes"] = {{{"mesh", 0}}};
  b.doc["scenes"] = {{{"nodes", {0}}}};
  write_text(dir / "uv.glb", b.glb());
  GltfDocument doc(dir / "uv.glb", 0);
  const GltfWorldScene w0 = doc.world_scene(0);
  const Mesh& m0 = w0.scene.meshes.at(0);
  ASSERT_EQ(m0.uvs.size(), 3u);
  EXPECT_FLOAT_EQ(m0.uvs[1].x, 1.0f);
  EXPECT_FLOAT_EQ(m0.uvs[2].y, 0.0f);  // v = 1 in glTF is v = 0 in the loader's v-up convention
  const GltfWorldScene w1 = GltfDocument(dir / "uv.glb", 1).world_scene(0);
  const Mesh& m1 = w1.scene.meshes.at(0);
  ASSERT_EQ(m1.uvs.size(), 3u);
  EXPECT_FLOAT_EQ(m1.uvs[0].x, 0.0f);  // zeros where the sparse part says nothing
  EXPECT_FLOAT_EQ(m1.uvs[2].x, 0.25f);
  EXPECT_FLOAT_EQ(m1.uvs[2].y, 0.5f);
}

TEST(GltfDocument, AnimationsExtensionsAndExtrasPassThroughASave) {
  TempDir dir;
  GlbFile g = parse_glb_file(instanced_cubes_glb());
  GltfBuilder b;
  b.doc = g.json;
  b.bin = g.bin;
  const int times = b.floats({0, 1}, "VEC2");  // two keyframes, stored as one VEC2 to keep the builder simple
  b.doc["accessors"][static_cast<std::size_t>(times)]["type"] = "SCALAR";
  b.doc["accessors"][static_cast<std::size_t>(times)]["count"] = 2;
  b.doc["accessors"][static_cast<std::size_t>(times)]["min"] = {0.0};
  b.doc["accessors"][static_cast<std::size_t>(times)]["max"] = {1.0};
  const int moves = b.floats({0, 0, 0, 0, 1, 0}, "VEC3");
  b.doc["animations"] = {{{"name", "Bob"},
                          {"samplers", {{{"input", times}, {"output", moves}, {"interpolation", "LINEAR"}}}},
                          {"channels", {{{"sampler", 0}, {"target", {{"node", 2}, {"path", "translation"}}}}}}}};
  b.doc["materials"][0]["extensions"] = {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4.0}}}};
  b.doc["materials"][0]["emissiveFactor"] = {1.0, 0.5, 0.0};
  b.doc["extensionsUsed"] = {"KHR_materials_emissive_strength"};
  b.doc["nodes"][1]["extras"] = {{"tag", "left cube"}};
  write_text(dir / "anim.glb", b.glb());
  GltfDocument doc(dir / "anim.glb", 0);
  doc.add_occlusion_map(0, std::string("\x89PNG\r\n\x1a\n", 8));  // bytes are carried, not decoded
  EXPECT_TRUE(doc.save_glb(dir / "out.glb").empty());
  const GlbFile out = parse_glb_file(read_text(dir / "out.glb"));
  EXPECT_EQ(out.json["animations"], b.doc["animations"]);
  EXPECT_EQ(out.json["nodes"], b.doc["nodes"]);
  EXPECT_EQ(out.json["extensionsUsed"], b.doc["extensionsUsed"]);
  EXPECT_EQ(out.json["materials"][0]["extensions"], b.doc["materials"][0]["extensions"]);
  EXPECT_EQ(out.json["materials"][0]["emissiveFactor"], b.doc["materials"][0]["emissiveFactor"]);
  // The animation's keyframes are the same bytes.
  EXPECT_EQ(glb_floats(out, moves), glb_floats(parse_glb_file(b.glb()), moves));
}

TEST(GltfDocument, TheGeneratorNamesAosVersionUnlessTheInputNamesItsOwn) {
  TempDir dir;
  GlbFile g = parse_glb_file(instanced_cubes_glb());
  GltfBuilder b;
  b.doc = g.json;
  b.bin = g.bin;
  b.doc["asset"].erase("generator");
  write_text(dir / "plain.glb", b.glb());
  GltfDocument plain(dir / "plain.glb", 0);
  plain.save_glb(dir / "plain-out.glb");
  EXPECT_EQ(parse_glb_file(read_text(dir / "plain-out.glb")).json["asset"]["generator"], std::string("ao bake ") + AO_VERSION_STRING);
  b.doc["asset"]["generator"] = "a modeller 4.2";  // the input's author keeps the credit
  write_text(dir / "named.glb", b.glb());
  GltfDocument named(dir / "named.glb", 0);
  named.save_glb(dir / "named-out.glb");
  EXPECT_EQ(parse_glb_file(read_text(dir / "named-out.glb")).json["asset"]["generator"], "a modeller 4.2");
}

TEST(GltfDocument, ImagesBesideTheInputAreEmbeddedAndOthersAreNotRead) {
  TempDir dir;
  fs::create_directories(dir / "scene" / "textures");
  const std::string png = std::string("\x89PNG\r\n\x1a\n", 8) + "not really a picture";
  write_text(dir / "scene" / "textures" / "albedo.png", png);
  write_text(dir / "outside.png", png);
  GlbFile g = parse_glb_file(instanced_cubes_glb());
  json j = g.json;
  // An external buffer beside the .gltf, two images in a subfolder, one of them missing.
  write_text(dir / "scene" / "cube.bin", g.bin);
  j["buffers"] = {{{"byteLength", g.bin.size()}, {"uri", "cube.bin"}}};
  j["images"] = {{{"uri", "textures/albedo.png"}}, {{"uri", "textures/missing.png"}}};
  j["textures"] = {{{"source", 0}}, {{"source", 1}}};
  j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  j["materials"][0]["emissiveTexture"] = {{"index", 1}};
  write_text(dir / "scene" / "cube.gltf", j.dump());
  GltfDocument doc(dir / "scene" / "cube.gltf", 0);
  ASSERT_EQ(doc.warnings().size(), 1u);
  EXPECT_NE(doc.warnings()[0].find("textures/missing.png"), std::string::npos) << doc.warnings()[0];
  doc.save_glb(dir / "out.glb");
  const GlbFile out = parse_glb_file(read_text(dir / "out.glb"));
  EXPECT_FALSE(out.json["buffers"][0].contains("uri"));
  ASSERT_EQ(out.json["images"].size(), 2u);
  EXPECT_EQ(glb_view(out, out.json["images"][0]["bufferView"].get<int>()), png);
  EXPECT_EQ(out.json["images"][0]["mimeType"], "image/png");
  EXPECT_EQ(out.json["images"][1]["uri"], "textures/missing.png");
  // An image or a buffer outside the folder is not read: the document is refused.
  const auto expect_refused = [&](const std::string& name) {
    write_text(dir / "scene" / name, j.dump());
    try {
      GltfDocument escape(dir / "scene" / name, 0);
      ADD_FAILURE() << "a file outside the glTF's folder was read";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      EXPECT_NE(what.find(name + ": "), std::string::npos) << what;
      EXPECT_NE(what.find("lies outside the asset's folder"), std::string::npos) << what;
    }
  };
  j["images"][1]["uri"] = "../outside.png";
  expect_refused("image-escape.gltf");
  j["images"][1]["uri"] = "textures/missing.png";
  write_text(dir / "outside.bin", g.bin);
  j["buffers"][0]["uri"] = "../outside.bin";
  expect_refused("buffer-escape.gltf");
}

TEST(GltfDocument, AnOcclusionTextureOfTheInputIsReplacedWithAWarning) {
  TempDir dir;
  GlbFile g = parse_glb_file(instanced_cubes_glb());
  GltfBuilder b;
  b.doc = g.json;
  b.bin = g.bin;
  b.doc["materials"][0]["occlusionTexture"] = {{"index", 0}, {"strength", 0.5}};
  b.doc["textures"] = {{{"source", 0}}};
  const std::string png = std::string("\x89PNG\r\n\x1a\n", 8);
  b.doc["images"] = {{{"uri", "data:image/png;base64,iVBORw0KGgo="}}};
  write_text(dir / "occ.glb", b.glb());
  GltfDocument doc(dir / "occ.glb", 0);
  doc.add_occlusion_map(0, png);
  const std::vector<std::string> w = doc.save_glb(dir / "out.glb");
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("'Red': its occlusion texture is replaced"), std::string::npos) << w[0];
  const GlbFile out = parse_glb_file(read_text(dir / "out.glb"));
  EXPECT_EQ(out.json["materials"][0]["occlusionTexture"], json({{"index", 1}}));  // the new texture, strength 1
  EXPECT_EQ(glb_view(out, out.json["images"][0]["bufferView"].get<int>()), png);  // the data: image, now in the binary chunk
}

TEST(GltfDocument, BadDocumentsAreOneLineInputErrors) {
  TempDir dir;
  const GlbFile g = parse_glb_file(instanced_cubes_glb());
  json index = g.json;
  index["meshes"][0]["primitives"][0]["indices"] = 99;
  json deep = g.json;
  json nest = json::array();
  for (int i = 0; i < 200; ++i) nest = json::array({nest});
  deep["extras"] = nest;
  json no_position = g.json;
  no_position["meshes"][0]["primitives"][0]["attributes"].erase("POSITION");
  json material = g.json;  // found by fuzz/fuzz_gltf_document.cpp: followed before it was checked
  material["meshes"][0]["primitives"][0]["material"] = 5;
  json draco = g.json;
  draco["extensionsUsed"] = draco["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  // Found by scripts/mutate: indices without a bufferView (zeros, valid glTF) reached tinygltf,
  // whose refusal ("accessor[N] invalid bufferView") was the message.
  json zero_indices = g.json;
  zero_indices["accessors"][zero_indices["meshes"][0]["primitives"][0]["indices"].get<int>()].erase("bufferView");
  const std::pair<std::string, std::string> cases[] = {
      {make_glb(zero_indices, g.bin), "mesh 0 primitive 0, indices accessor"},
      {make_glb(index, g.bin), "99"},
      {make_glb(material, g.bin), "material 5, the file has 1"},
      {make_glb(draco, g.bin), "compressed with KHR_draco_mesh_compression"},
      {make_glb(deep, g.bin), "nests deeper"},
      {make_glb(no_position, g.bin), "bad.glb"},
      {"glTF", "bad.glb"},
      {"", "empty"},
  };
  for (const auto& [bytes, needle] : cases) {
    write_text(dir / "bad.glb", bytes);
    try {
      GltfDocument doc(dir / "bad.glb", 0);
      ADD_FAILURE() << "accepted a document that should fail with '" << needle << "'";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      EXPECT_NE(what.find(needle), std::string::npos) << what;
      EXPECT_EQ(what.rfind((dir / "bad.glb").string(), 0), 0u) << what;
    }
  }
}

}  // namespace
}  // namespace ao::test
