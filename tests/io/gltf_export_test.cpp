// SPDX-License-Identifier: Apache-2.0
// The .glb written by `ao bake --gltf` (gltf_export.h): the binary container parsed here by hand
// (glTF 2.0 spec, "Binary glTF Layout"), the JSON checked for the occlusion texture, the embedded
// PNG decoded, and the file loaded back with assimp.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <regex>

#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/io/gltf_export.h"
#include "ao/io/image_io.h"
#include "ao/io/mesh_io.h"
#include "ao/scene/procedural.h"
#include "ao/version.h"
#include "support/run.h"

namespace ao {
namespace {

std::uint32_t u32(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, s.data() + at, 4);
  return v;
}

struct Glb {
  std::uint32_t magic = 0, version = 0, length = 0;
  std::uint32_t json_length = 0, json_type = 0, bin_length = 0, bin_type = 0;
  nlohmann::json json;
  std::string bin;
};

Glb parse_glb(const std::string& f) {
  Glb g;
  if (f.size() < 28) throw std::runtime_error("GLB shorter than its headers");
  g.magic = u32(f, 0), g.version = u32(f, 4), g.length = u32(f, 8);
  g.json_length = u32(f, 12), g.json_type = u32(f, 16);
  if (20 + g.json_length + 8 > f.size()) throw std::runtime_error("JSON chunk overruns the file");
  g.json = nlohmann::json::parse(f.substr(20, g.json_length));
  const std::size_t bin_at = 20 + g.json_length;
  g.bin_length = u32(f, bin_at), g.bin_type = u32(f, bin_at + 4);
  if (bin_at + 8 + g.bin_length > f.size()) throw std::runtime_error("BIN chunk overruns the file");
  g.bin = f.substr(bin_at + 8, g.bin_length);
  return g;
}

// A floor quad with UVs over a part of the map, and a box without UVs standing on it.
Scene textured_and_untextured() {
  Scene s;
  s.name = "gltf-test";
  Mesh quad = make_quad({-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}, {0.5f, 0.25f, 0.125f});
  quad.name = "floor";
  quad.uvs = {{0.1f, 0.2f}, {0.9f, 0.2f}, {0.9f, 0.7f}, {0.1f, 0.7f}};
  s.meshes.push_back(quad);
  Mesh box = make_box({-0.3f, 0, -0.3f}, {0.3f, 0.6f, 0.3f});
  box.name = "box";
  s.meshes.push_back(box);
  validate_and_prepare(s);
  return s;
}

// PNG bytes of a small gradient, as the CLI produces them (write_image, then the file's bytes).
std::string gradient_png(const test::TempDir& dir, Image<float>& img) {
  img = Image<float>(8, 4, 0.0f);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) img(x, y) = static_cast<float>(x + 8 * y) / 31.0f;
  write_image(dir / "map.png", img);
  return test::read_text(dir / "map.png");
}

TEST(GltfExport, ContainerHeaderAndChunksFollowTheSpec) {
  test::TempDir dir;
  Image<float> img;
  const std::string png = gradient_png(dir, img);
  const Scene s = textured_and_untextured();
  write_ao_glb(dir / "out.glb", s, png);
  const std::string f = test::read_text(dir / "out.glb");
  const Glb g = parse_glb(f);
  EXPECT_EQ(g.magic, 0x46546C67u);  // "glTF"
  EXPECT_EQ(g.version, 2u);
  EXPECT_EQ(g.length, f.size());
  EXPECT_EQ(g.json_type, 0x4E4F534Au);  // "JSON"
  EXPECT_EQ(g.bin_type, 0x004E4942u);   // "BIN\0"
  EXPECT_EQ(g.json_length % 4, 0u);
  EXPECT_EQ(g.bin_length % 4, 0u);
  EXPECT_EQ(20 + g.json_length + 8 + g.bin_length, f.size());
  // The JSON chunk is padded with spaces (0x20), per the spec.
  const std::string raw_json = f.substr(20, g.json_length);
  EXPECT_EQ(raw_json.find('\0'), std::string::npos);
  // One buffer, the BIN chunk, at least as long as it says.
  ASSERT_EQ(g.json["buffers"].size(), 1u);
  EXPECT_FALSE(g.json["buffers"][0].contains("uri"));
  EXPECT_LE(g.json["buffers"][0]["byteLength"].get<std::size_t>(), g.bin.size());
  EXPECT_EQ(g.json["asset"]["version"], "2.0");
  // The generator names the tool and the version that wrote the file.
  EXPECT_EQ(g.json["asset"]["generator"], std::string("ao bake ") + AO_VERSION_STRING);
  EXPECT_TRUE(std::regex_match(g.json["asset"]["generator"].get<std::string>(), std::regex(R"(ao bake [0-9]+\.[0-9]+\.[0-9]+)")));
  // Every buffer view inside the buffer; those used by accessors start 4-byte aligned.
  for (const auto& v : g.json["bufferViews"]) {
    const std::size_t off = v.value("byteOffset", std::size_t{0}), len = v["byteLength"].get<std::size_t>();
    EXPECT_LE(off + len, g.bin.size());
  }
  for (const auto& a : g.json["accessors"]) {
    const auto& v = g.json["bufferViews"][a["bufferView"].get<std::size_t>()];
    EXPECT_EQ(v.value("byteOffset", std::size_t{0}) % 4, 0u);
    const int comp = a["componentType"];
    EXPECT_TRUE(comp == 5126 || comp == 5125) << comp;
    const std::size_t ncomp = a["type"] == "VEC3" ? 3 : a["type"] == "VEC2" ? 2 : 1;
    EXPECT_EQ(a["count"].get<std::size_t>() * ncomp * 4, v["byteLength"].get<std::size_t>());
  }
}

TEST(GltfExport, OcclusionTextureIsTheEmbeddedPngAndDecodes) {
  test::TempDir dir;
  Image<float> img;
  const std::string png = gradient_png(dir, img);
  const Scene s = textured_and_untextured();
  write_ao_glb(dir / "out.glb", s, png);
  const Glb g = parse_glb(test::read_text(dir / "out.glb"));
  const auto& j = g.json;
  ASSERT_EQ(j["materials"].size(), 2u);
  // Mesh 0 has UVs: its material carries the map; mesh 1 has none and gets no texture.
  ASSERT_TRUE(j["materials"][0].contains("occlusionTexture"));
  EXPECT_FALSE(j["materials"][1].contains("occlusionTexture"));
  EXPECT_EQ(j["materials"][0]["occlusionTexture"].value("texCoord", 0), 0);
  const auto& base = j["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"];
  EXPECT_FLOAT_EQ(base[0].get<float>(), 0.5f);
  EXPECT_FLOAT_EQ(base[1].get<float>(), 0.25f);
  const std::size_t tex = j["materials"][0]["occlusionTexture"]["index"];
  ASSERT_LT(tex, j["textures"].size());
  const std::size_t src = j["textures"][tex]["source"];
  ASSERT_LT(src, j["images"].size());
  const auto& image = j["images"][src];
  EXPECT_EQ(image["mimeType"], "image/png");
  ASSERT_TRUE(image.contains("bufferView"));
  const auto& view = j["bufferViews"][image["bufferView"].get<std::size_t>()];
  const std::size_t off = view.value("byteOffset", std::size_t{0}), len = view["byteLength"];
  ASSERT_LE(off + len, g.bin.size());
  const std::string embedded = g.bin.substr(off, len);
  EXPECT_EQ(embedded, png);
  // It decodes to the map we wrote.
  test::write_text(dir / "embedded.png", embedded);
  const Image<float> back = read_image(dir / "embedded.png");
  ASSERT_EQ(back.width(), img.width());
  ASSERT_EQ(back.height(), img.height());
  for (std::size_t i = 0; i < img.size(); ++i) EXPECT_NEAR(back[i], img[i], 0.5 / 255.0 + 1e-6) << i;
  // The primitive of mesh 0 has TEXCOORD_0, the one of mesh 1 does not.
  EXPECT_TRUE(j["meshes"][0]["primitives"][0]["attributes"].contains("TEXCOORD_0"));
  EXPECT_FALSE(j["meshes"][1]["primitives"][0]["attributes"].contains("TEXCOORD_0"));
}

TEST(GltfExport, AssimpLoadsTheSameTrianglesAndUvs) {
  test::TempDir dir;
  Image<float> img;
  const std::string png = gradient_png(dir, img);
  const Scene s = textured_and_untextured();
  write_ao_glb(dir / "out.glb", s, png);
  const Scene back = load_scene_file(dir / "out.glb");
  EXPECT_EQ(back.triangle_count(), s.triangle_count());
  EXPECT_EQ(back.meshes.size(), s.meshes.size());
  // UVs were flipped to glTF's top-left origin on writing and are flipped back by the reader:
  // every vertex of the floor gets its original UV (matched by position).
  const Mesh* floor = nullptr;
  for (const Mesh& m : back.meshes)
    if (!m.uvs.empty()) floor = &m;
  ASSERT_NE(floor, nullptr);
  const Mesh& orig = s.meshes[0];
  for (std::size_t v = 0; v < floor->positions.size(); ++v) {
    bool found = false;
    for (std::size_t o = 0; o < orig.positions.size(); ++o)
      if (length(orig.positions[o] - floor->positions[v]) < 1e-6f) {
        found = true;
        EXPECT_NEAR(floor->uvs[v].x, orig.uvs[o].x, 1e-6);
        EXPECT_NEAR(floor->uvs[v].y, orig.uvs[o].y, 1e-6);
      }
    EXPECT_TRUE(found) << v;
  }
}

TEST(GltfExport, GltfFilesAreKnownByExtensionOrMagic) {
  const test::TempDir dir;
  test::write_text(dir / "a.GLTF", "{}");
  EXPECT_TRUE(is_gltf_file(dir / "a.GLTF"));
  test::write_text(dir / "renamed.bin", std::string("glTF\x02\0\0\0", 8));
  EXPECT_TRUE(is_gltf_file(dir / "renamed.bin"));
  test::write_text(dir / "mesh.obj", "v 0 0 0\n");
  EXPECT_FALSE(is_gltf_file(dir / "mesh.obj"));
  EXPECT_FALSE(is_gltf_file(dir / "missing.dat"));
}

TEST(GltfExport, PerVertexAoIsColor0OfEveryPrimitive) {
  const test::TempDir dir;
  const Scene s = textured_and_untextured();
  std::vector<float> ao(s.vertex_count());
  for (std::size_t i = 0; i < ao.size(); ++i) ao[i] = static_cast<float>(i) / static_cast<float>(ao.size());
  write_ao_glb(dir / "out.glb", s, "", &ao);
  const Glb g = parse_glb(test::read_text(dir / "out.glb"));
  EXPECT_FALSE(g.json.contains("textures"));  // no map given: no occlusion texture
  std::size_t first = 0;
  for (std::size_t mi = 0; mi < s.meshes.size(); ++mi) {
    const auto& attr = g.json["meshes"][mi]["primitives"][0]["attributes"];
    ASSERT_TRUE(attr.contains("COLOR_0"));
    const auto& a = g.json["accessors"][attr["COLOR_0"].get<std::size_t>()];
    EXPECT_EQ(a["type"], "VEC3");
    EXPECT_EQ(a["componentType"], 5126);
    ASSERT_EQ(a["count"].get<std::size_t>(), s.meshes[mi].positions.size());
    const auto& v = g.json["bufferViews"][a["bufferView"].get<std::size_t>()];
    std::vector<Vec3> c(s.meshes[mi].positions.size());
    std::memcpy(c.data(), g.bin.data() + v.value("byteOffset", std::size_t{0}), c.size() * sizeof(Vec3));
    for (std::size_t k = 0; k < c.size(); ++k) {
      EXPECT_EQ(c[k].x, ao[first + k]);
      EXPECT_EQ(c[k].z, ao[first + k]);
    }
    first += c.size();
  }
  std::vector<float> wrong(3, 1.0f);
  EXPECT_THROW(write_ao_glb(dir / "bad.glb", s, "", &wrong), InputError);
}

}  // namespace
}  // namespace ao
