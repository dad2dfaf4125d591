// The .glb written by `ao bake --gltf` (gltf_export.h): the binary container parsed here by hand
// (glTF 2.0 spec, "Binary glTF Layout"), the JSON checked for the occlusion texture, the embedded
// PNG decoded, and the file loaded back with assimp.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>

#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/io/gltf_export.h"
#include "ao/io/image_io.h"
#include "ao/io/mesh_io.h"
#include "ao/scene/procedural.h"
#include "support/bytes.h"
#include "support/run.h"

namespace ao {
namespace {

using test::base64;

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

// --- glTF input: its materials are kept -------------------------------------------------------

// A unit quad (z = 0, facing +z) with TEXCOORD_0 over [0.1, 0.4]^2 and TEXCOORD_1 over [0.5, 0.9]^2
// (glTF's v down), embedded base64 buffer, using `material` (JSON) and `images` (JSON array).
nlohmann::json quad_gltf(const nlohmann::json& material, const nlohmann::json& images = nlohmann::json::array()) {
  nlohmann::json g = nlohmann::json::parse(R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],
  "nodes":[{"mesh":0}],
  "meshes":[{"name":"quad","primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1,"TEXCOORD_1":2},"indices":3,"material":0}]}],
  "buffers":[{"byteLength":124,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAACAPwAAgD8AAAAAAAAAAAAAgD8AAAAAzczMPc3MzD3NzMw+zczMPc3MzD7NzMw+zczMPc3MzD4AAAA/AAAAP2ZmZj8AAAA/ZmZmP2ZmZj8AAAA/ZmZmPwAAAQACAAAAAgADAA=="}],
  "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":32},
                 {"buffer":0,"byteOffset":80,"byteLength":32},{"buffer":0,"byteOffset":112,"byteLength":12}],
  "accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
               {"bufferView":1,"componentType":5126,"count":4,"type":"VEC2"},
               {"bufferView":2,"componentType":5126,"count":4,"type":"VEC2"},
               {"bufferView":3,"componentType":5123,"count":6,"type":"SCALAR"}]})");
  g["materials"] = {material};
  if (!images.empty()) {
    g["images"] = images;
    g["samplers"] = {{{"wrapS", 33071}, {"wrapT", 33648}, {"magFilter", 9728}}};
    g["textures"] = nlohmann::json::array();
    for (std::size_t i = 0; i < images.size(); ++i) g["textures"].push_back({{"source", i}, {"sampler", 0}});
  }
  return g;
}

// The floats of a VEC2 accessor of the output.
std::vector<Vec2> read_vec2(const Glb& g, std::size_t accessor) {
  const auto& a = g.json["accessors"][accessor];
  EXPECT_EQ(a["type"], "VEC2");
  const auto& v = g.json["bufferViews"][a["bufferView"].get<std::size_t>()];
  std::vector<Vec2> out(a["count"].get<std::size_t>());
  std::memcpy(out.data(), g.bin.data() + v.value("byteOffset", std::size_t{0}), out.size() * sizeof(Vec2));
  return out;
}

// Bakes nothing: loads `gltf` like `ao bake` does, then exports it with `png` as the map.
Glb export_gltf_input(const test::TempDir& dir, const nlohmann::json& gltf, const std::string& png, int uv_set, GltfSource* source_out = nullptr) {
  test::write_text(dir / "in.gltf", gltf.dump());
  const Scene scene = load_scene_file(dir / "in.gltf", {.uv_set = uv_set});
  EXPECT_TRUE(is_gltf_file(dir / "in.gltf"));
  const GltfSource source = load_gltf_materials(dir / "in.gltf", scene, uv_set);
  if (source_out) *source_out = source;
  write_ao_glb(dir / "out.glb", scene, png, &source);
  return parse_glb(test::read_text(dir / "out.glb"));
}

TEST(GltfExport, GltfInputKeepsItsMaterialFactorsAndGetsTheOcclusionTexture) {
  test::TempDir dir;
  Image<float> img;
  const std::string png = gradient_png(dir, img);
  const nlohmann::json material = {{"name", "Painted metal"},
                                   {"pbrMetallicRoughness", {{"baseColorFactor", {0.2, 0.4, 0.6, 0.8}}, {"metallicFactor", 0.3}, {"roughnessFactor", 0.7}}},
                                   {"emissiveFactor", {0.1, 0.2, 0.3}},
                                   {"alphaMode", "MASK"},
                                   {"alphaCutoff", 0.25},
                                   {"doubleSided", true}};
  GltfSource source;
  const Glb g = export_gltf_input(dir, quad_gltf(material), png, 0, &source);
  EXPECT_TRUE(source.warnings.empty()) << source.warnings.front();
  ASSERT_EQ(g.json["materials"].size(), 1u);
  const auto& m = g.json["materials"][0];
  EXPECT_EQ(m["name"], "Painted metal");
  const auto& pbr = m["pbrMetallicRoughness"];
  const float base[4] = {0.2f, 0.4f, 0.6f, 0.8f};
  ASSERT_EQ(pbr["baseColorFactor"].size(), 4u);
  for (int k = 0; k < 4; ++k) EXPECT_FLOAT_EQ(pbr["baseColorFactor"][k].get<float>(), base[k]) << k;
  EXPECT_FLOAT_EQ(pbr["metallicFactor"].get<float>(), 0.3f);
  EXPECT_FLOAT_EQ(pbr["roughnessFactor"].get<float>(), 0.7f);
  ASSERT_EQ(m["emissiveFactor"].size(), 3u);
  EXPECT_FLOAT_EQ(m["emissiveFactor"][2].get<float>(), 0.3f);
  EXPECT_EQ(m["alphaMode"], "MASK");
  EXPECT_FLOAT_EQ(m["alphaCutoff"].get<float>(), 0.25f);
  EXPECT_EQ(m["doubleSided"], true);
  EXPECT_FALSE(m.contains("extensions"));  // not unlit, no emissive strength
  // The map was added as the occlusion texture, on the baked set (TEXCOORD_0), and it is the PNG.
  ASSERT_TRUE(m.contains("occlusionTexture"));
  EXPECT_EQ(m["occlusionTexture"]["texCoord"], 0);
  const std::size_t image = g.json["textures"][m["occlusionTexture"]["index"].get<std::size_t>()]["source"];
  const auto& view = g.json["bufferViews"][g.json["images"][image]["bufferView"].get<std::size_t>()];
  EXPECT_EQ(g.bin.substr(view["byteOffset"], view["byteLength"]), png);
  // No textures of its own, and only the baked UV set is written.
  EXPECT_FALSE(pbr.contains("baseColorTexture"));
  const auto& attributes = g.json["meshes"][0]["primitives"][0]["attributes"];
  EXPECT_TRUE(attributes.contains("TEXCOORD_0"));
  EXPECT_FALSE(attributes.contains("TEXCOORD_1"));
  // assimp reads the output back with the material's colour.
  const Scene back = load_scene_file(dir / "out.glb");
  ASSERT_EQ(back.meshes.size(), 1u);
  EXPECT_NEAR(back.meshes[0].albedo.y, 0.4f, 1e-6f);
}

TEST(GltfExport, GltfInputBaseColorTextureIsCopiedWithItsUvSet) {
  test::TempDir dir;
  Image<float> img;
  const std::string ao_png = gradient_png(dir, img);
  // A distinct small PNG as the input's base-colour texture (embedded as a data URI).
  Image<float> colour(2, 2, 0.25f);
  write_image(dir / "colour.png", colour);
  const std::string colour_png = test::read_text(dir / "colour.png");
  ASSERT_NE(colour_png, ao_png);
  const nlohmann::json images = {{{"uri", "data:image/png;base64," + base64(colour_png)}}};
  const nlohmann::json material = {{"name", "textured"},
                                   {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}, {"texCoord", 1}}}, {"metallicFactor", 0.0}}}};
  for (const int uv_set : {0, 1}) {
    SCOPED_TRACE("uv_set " + std::to_string(uv_set));
    GltfSource source;
    const Glb g = export_gltf_input(dir, quad_gltf(material, images), ao_png, uv_set, &source);
    EXPECT_TRUE(source.warnings.empty()) << source.warnings.front();
    const auto& m = g.json["materials"][0];
    EXPECT_EQ(m["name"], "textured");
    EXPECT_FLOAT_EQ(m["pbrMetallicRoughness"]["metallicFactor"].get<float>(), 0.0f);
    ASSERT_TRUE(m["pbrMetallicRoughness"].contains("baseColorTexture"));
    ASSERT_TRUE(m.contains("occlusionTexture"));
    EXPECT_EQ(m["occlusionTexture"]["texCoord"], 0);
    const auto& bct = m["pbrMetallicRoughness"]["baseColorTexture"];
    // The base-colour texture's image is the input's PNG, its sampler the input's.
    const auto& texture = g.json["textures"][bct["index"].get<std::size_t>()];
    const auto& image = g.json["images"][texture["source"].get<std::size_t>()];
    EXPECT_EQ(image["mimeType"], "image/png");
    const auto& view = g.json["bufferViews"][image["bufferView"].get<std::size_t>()];
    EXPECT_EQ(g.bin.substr(view["byteOffset"], view["byteLength"]), colour_png);
    const auto& sampler = g.json["samplers"][texture["sampler"].get<std::size_t>()];
    EXPECT_EQ(sampler["wrapS"], 33071);
    EXPECT_EQ(sampler["wrapT"], 33648);
    EXPECT_EQ(sampler["magFilter"], 9728);
    // TEXCOORD_0 is always the baked set; the texture's set (the input's TEXCOORD_1) is either the
    // baked one (uv_set 1) or written after it.
    const auto& attributes = g.json["meshes"][0]["primitives"][0]["attributes"];
    const std::vector<Vec2> t0 = read_vec2(g, attributes["TEXCOORD_0"]);
    ASSERT_EQ(t0.size(), 4u);
    const float baked_lo = uv_set == 0 ? 0.1f : 0.5f;
    for (const Vec2& t : t0) {
      EXPECT_GE(t.x, baked_lo - 1e-6f);
      EXPECT_LE(t.x, baked_lo + 0.4f + 1e-6f);
      EXPECT_GE(t.y, baked_lo - 1e-6f);  // back in glTF's v-down convention
      EXPECT_LE(t.y, baked_lo + 0.4f + 1e-6f);
    }
    if (uv_set == 1) {
      EXPECT_EQ(bct["texCoord"], 0);
      EXPECT_FALSE(attributes.contains("TEXCOORD_1"));
    } else {
      EXPECT_EQ(bct["texCoord"], 1);
      ASSERT_TRUE(attributes.contains("TEXCOORD_1"));
      for (const Vec2& t : read_vec2(g, attributes["TEXCOORD_1"])) {
        EXPECT_GE(t.x, 0.5f - 1e-6f);
        EXPECT_LE(t.x, 0.9f + 1e-6f);
        EXPECT_GE(t.y, 0.5f - 1e-6f);
        EXPECT_LE(t.y, 0.9f + 1e-6f);
      }
    }
  }
}

TEST(GltfExport, GltfPrimitiveWithoutMaterialGetsAFreshOne) {
  test::TempDir dir;
  Image<float> img;
  const std::string png = gradient_png(dir, img);
  nlohmann::json gltf = quad_gltf({{"name", "unused"}});
  gltf["meshes"][0]["primitives"][0].erase("material");
  const Glb g = export_gltf_input(dir, gltf, png, 0);
  const auto& m = g.json["materials"][0];
  EXPECT_EQ(m["name"], "quad");
  EXPECT_FLOAT_EQ(m["pbrMetallicRoughness"]["metallicFactor"].get<float>(), 0.0f);
  EXPECT_TRUE(m.contains("occlusionTexture"));
}

}  // namespace
}  // namespace ao

namespace ao {
namespace {

TEST(GltfExport, PerVertexAoIsColor0OfEveryPrimitive) {
  const test::TempDir dir;
  const Scene s = textured_and_untextured();
  std::vector<float> ao(s.vertex_count());
  for (std::size_t i = 0; i < ao.size(); ++i) ao[i] = static_cast<float>(i) / static_cast<float>(ao.size());
  write_ao_glb(dir / "out.glb", s, "", nullptr, &ao);
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
  EXPECT_THROW(write_ao_glb(dir / "bad.glb", s, "", nullptr, &wrong), InputError);
}

}  // namespace
}  // namespace ao
