// SPDX-License-Identifier: Apache-2.0
// `ao bake` on glTF inputs with --gltf / --per-vertex .glb: the document's round trip
// (gltf_document.h, bake_gltf.h). The inputs are built in the test (support/gltf_docs.h): an
// instanced pair of cubes in a node hierarchy, and a material shared by three meshes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>

#include "ao/io/image_io.h"
#include "support/gltf_docs.h"
#include "support/run.h"

namespace ao::test {
namespace {

namespace fs = std::filesystem;

const std::string kRays = " --samples 64 --padding 2 -s 48 ";


// The embedded image `image` of a GLB, decoded.
Image<float> embedded_map(const TempDir& dir, const GlbFile& g, int image) {
  const nlohmann::json& im = g.json["images"][static_cast<std::size_t>(image)];
  EXPECT_EQ(im["mimeType"], "image/png");
  write_text(dir / "embedded.png", glb_view(g, im["bufferView"].get<int>()));
  return read_image(dir / "embedded.png");
}

// Mean of the map over the UV cell of face f of GltfBuilder::box (glTF's UVs: texel (x, y) has its
// centre at u = (x + 0.5) / W, v = (y + 0.5) / H), one texel inside the cell's edges.
double face_mean(const Image<float>& map, int f) {
  const double u0 = (f % 3) / 3.0 + 0.02, u1 = (f % 3 + 1) / 3.0 - 0.02, v0 = (f / 3) / 2.0 + 0.02, v1 = (f / 3 + 1) / 2.0 - 0.02;
  double sum = 0;
  int n = 0;
  for (int y = 0; y < map.height(); ++y)
    for (int x = 0; x < map.width(); ++x) {
      const double u = (x + 0.5) / map.width(), v = (y + 0.5) / map.height();
      const double du = 1.0 / map.width(), dv = 1.0 / map.height();
      if (u > u0 + du && u < u1 - du && v > v0 + dv && v < v1 - dv) sum += map(x, y), ++n;
    }
  EXPECT_GT(n, 10);
  return sum / std::max(n, 1);
}

TEST(BakeGltf, InstancedMeshIsBakedOnceAndTheNodesPassThrough) {
  TempDir dir;
  write_text(dir / "pair.glb", instanced_cubes_glb());
  const RunResult r = run_ao("bake pair.glb --gltf out.glb --json" + kRays, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const GlbFile in = parse_glb_file(instanced_cubes_glb());
  const GlbFile out = parse_glb_file(read_text(dir / "out.glb"));
  // Nodes, names, hierarchy, transforms and mesh references as they were; one mesh, one map.
  EXPECT_EQ(out.json["nodes"], in.json["nodes"]);
  EXPECT_EQ(out.json["scenes"], in.json["scenes"]);
  ASSERT_EQ(out.json["meshes"].size(), 1u);
  EXPECT_EQ(out.json["meshes"][0]["name"], "Cube");
  EXPECT_EQ(out.json["meshes"][0]["primitives"][0]["attributes"], in.json["meshes"][0]["primitives"][0]["attributes"]);
  ASSERT_EQ(out.json["images"].size(), 1u);
  ASSERT_EQ(out.json["textures"].size(), 1u);
  const auto summary = nlohmann::json::parse(r.out);
  ASSERT_EQ(summary["maps"].size(), 1u);
  EXPECT_EQ(summary["maps"][0]["instances"], 2);
  // The material keeps its factors and gains the occlusion texture, TEXCOORD_0.
  ASSERT_EQ(out.json["materials"].size(), 1u);
  const nlohmann::json& mat = out.json["materials"][0];
  EXPECT_EQ(mat["name"], "Red");
  EXPECT_EQ(mat["pbrMetallicRoughness"], in.json["materials"][0]["pbrMetallicRoughness"]);
  EXPECT_EQ(mat["occlusionTexture"]["index"], 0);
  EXPECT_EQ(mat["occlusionTexture"].value("texCoord", 0), 0);
  EXPECT_EQ(out.json["meshes"][0]["primitives"][0]["material"], 0);
  // The map is of the first instance (Left) with Right occluding: its +x face (face 1) looks at
  // Right from 0.2 away, its -x face (face 0) sees only sky (V = 1 exactly, up to the padding of
  // neighbouring charts, which the one-texel inset keeps out). With the other instance averaged in,
  // or missing as an occluder, both faces would be alike.
  const Image<float> map = embedded_map(dir, out, 0);
  EXPECT_EQ(map.width(), 48);
  const double open = face_mean(map, 0), facing = face_mean(map, 1);
  EXPECT_GT(open, 0.97);
  // From the middle of the +x face, the neighbour's face 0.2 away (1 x 1) covers most of the
  // cosine-weighted hemisphere: V there is ~0.1, ~0.35 at the edges of the face.
  EXPECT_LT(facing, 0.5);
  // Top, bottom, front and back lie in the planes of Right's faces: Right is at their horizon, so
  // they are open too.
  for (int f = 2; f < 6; ++f) EXPECT_GT(face_mean(map, f), 0.97) << "face " << f;
}

// A cube (UVs) turned 30 degrees about y and standing on a plate without UVs: one instance each.
std::string cube_on_plate_glb() {
  GltfBuilder b;
  const float clo[3] = {-0.5f, -0.5f, -0.5f}, chi[3] = {0.5f, 0.5f, 0.5f};
  const float plo[3] = {-2.0f, -0.1f, -2.0f}, phi[3] = {2.0f, 0.0f, 2.0f};
  b.doc["meshes"] = {{{"name", "Cube"}, {"primitives", {b.box(clo, chi, true, -1)}}}, {{"name", "Plate"}, {"primitives", {b.box(plo, phi, false, -1)}}}};
  const double s = std::sin(0.2617993877991494), c = std::cos(0.2617993877991494);  // half of 30 degrees
  b.doc["nodes"] = {{{"name", "Turned"}, {"mesh", 0}, {"rotation", {0.0, s, 0.0, c}}, {"translation", {0.0, 0.5, 0.0}}}, {{"name", "Ground"}, {"mesh", 1}}};
  b.doc["scenes"] = {{{"nodes", {0, 1}}}};
  return b.glb();
}

TEST(BakeGltf, SingleInstanceRoundTripAgreesWithTheFlattenedBake) {
  // Without instancing the round trip bakes the same surfaces as the flattened path (assimp,
  // pre-transformed vertices, `-o` alone): same triangles, UVs, seed and texel samples, so the maps
  // agree up to the float rounding of the transforms (done in double here, in float by assimp),
  // which can move a ray that grazes an edge.
  TempDir dir;
  write_text(dir / "scene.glb", cube_on_plate_glb());
  ASSERT_EQ(run_ao("bake scene.glb -o flat.exr -q" + kRays, dir.path()).exit_code, 0);
  ASSERT_EQ(run_ao("bake scene.glb --gltf rt.glb -o rt.exr -q" + kRays, dir.path()).exit_code, 0);
  const Image<float> flat = read_image(dir / "flat.exr"), rt = read_image(dir / "rt.exr");
  ASSERT_EQ(flat.width(), rt.width());
  double sum = 0, worst = 0;
  for (std::size_t i = 0; i < flat.size(); ++i) {
    sum += std::abs(flat[i] - rt[i]);
    worst = std::max(worst, static_cast<double>(std::abs(flat[i] - rt[i])));
  }
  EXPECT_LT(sum / static_cast<double>(flat.size()), 1e-3) << "worst texel differs by " << worst;
  // The bottom face (face 2, -y) rests on the plate: closed.
  EXPECT_LT(face_mean(rt, 2), 0.05);
}

TEST(BakeGltf, SharedMaterialIsClonedPerMapAndKeptWhereNothingIsBaked) {
  TempDir dir;
  write_text(dir / "shared.glb", shared_material_glb());
  const RunResult r = run_ao("bake shared.glb --gltf out.glb --json" + kRays, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const GlbFile out = parse_glb_file(read_text(dir / "out.glb"));
  ASSERT_EQ(out.json["images"].size(), 2u);  // Cube and Plate have UVs; Post has none
  const nlohmann::json& meshes = out.json["meshes"];
  const int cube = meshes[0]["primitives"][0]["material"], plate = meshes[1]["primitives"][0]["material"], post = meshes[2]["primitives"][0]["material"];
  EXPECT_NE(cube, plate);
  EXPECT_EQ(post, 0);
  EXPECT_FALSE(out.json["materials"][0].contains("occlusionTexture"));
  const nlohmann::json& mc = out.json["materials"][static_cast<std::size_t>(cube)];
  const nlohmann::json& mp = out.json["materials"][static_cast<std::size_t>(plate)];
  for (const nlohmann::json* m : {&mc, &mp}) {
    EXPECT_EQ((*m)["pbrMetallicRoughness"]["baseColorFactor"], nlohmann::json({0.2, 0.5, 0.9, 1.0}));
    EXPECT_EQ((*m)["doubleSided"], true);
    ASSERT_TRUE(m->contains("occlusionTexture"));
  }
  EXPECT_NE(mc["occlusionTexture"]["index"], mp["occlusionTexture"]["index"]);
  // The plate's map is darker where the cube stands on it than the cube's open top is.
  const auto summary = nlohmann::json::parse(r.out);
  ASSERT_EQ(summary["maps"].size(), 2u);
}

TEST(BakeGltf, SixteenBitPngIsEmbeddedWhenAsked) {
  TempDir dir;
  write_text(dir / "pair.glb", instanced_cubes_glb());
  ASSERT_EQ(run_ao("bake pair.glb --gltf out.glb --png-bits 16 -q" + kRays, dir.path()).exit_code, 0);
  const GlbFile out = parse_glb_file(read_text(dir / "out.glb"));
  const std::string png = glb_view(out, out.json["images"][0]["bufferView"].get<int>());
  ASSERT_GT(png.size(), 25u);
  EXPECT_EQ(png.substr(0, 8), "\x89PNG\r\n\x1a\n");
  EXPECT_EQ(static_cast<unsigned char>(png[24]), 16);  // IHDR bit depth
}

TEST(BakeGltf, PerVertexGlbIsColor0OfTheFirstInstance) {
  TempDir dir;
  write_text(dir / "pair.glb", instanced_cubes_glb());
  ASSERT_EQ(run_ao("bake pair.glb --per-vertex v.glb -q --samples 256", dir.path()).exit_code, 0);
  const GlbFile in = parse_glb_file(instanced_cubes_glb());
  const GlbFile out = parse_glb_file(read_text(dir / "v.glb"));
  EXPECT_EQ(out.json["nodes"], in.json["nodes"]);
  EXPECT_FALSE(out.json.contains("images"));
  const nlohmann::json& attributes = out.json["meshes"][0]["primitives"][0]["attributes"];
  ASSERT_TRUE(attributes.contains("COLOR_0"));
  const std::vector<float> c = glb_floats(out, attributes["COLOR_0"].get<int>());
  ASSERT_EQ(c.size(), 24u * 3u);
  // Vertices 0-3 are the -x face's corners (open: each sees a half-space, V = 1), 4-7 the +x
  // face's, which look at Right 0.2 away (corners: about a quarter of the hemisphere blocked).
  for (int v = 0; v < 4; ++v) EXPECT_GT(c[3 * v], 0.95f) << v;
  for (int v = 4; v < 8; ++v) EXPECT_LT(c[3 * v], 0.85f) << v;
}

TEST(BakeGltf, OMapIsWrittenForOneBakedMeshAndRefusedForSeveral) {
  TempDir dir;
  write_text(dir / "pair.glb", instanced_cubes_glb());
  ASSERT_EQ(run_ao("bake pair.glb --gltf out.glb -o ao.png -q" + kRays, dir.path()).exit_code, 0);
  EXPECT_EQ(read_image(dir / "ao.png").width(), 48);
  write_text(dir / "shared.glb", shared_material_glb());
  const RunResult r = run_ao("bake shared.glb --gltf out2.glb -o ao2.png" + kRays, dir.path());
  expect_one_line_error(r, "-o names one map");
  EXPECT_FALSE(fs::exists(dir / "out2.glb"));
  EXPECT_FALSE(fs::exists(dir / "ao2.png"));
}

TEST(BakeGltf, BadDocumentsAreOneLineErrorsAndWriteNothing) {
  TempDir dir;
  const std::string good = instanced_cubes_glb();
  GlbFile g = parse_glb_file(good);
  // Index past the vertex count, accessor past its buffer, a node cycle, broken JSON, a truncated
  // file, a mesh without the UV set asked for.
  nlohmann::json bad_index = g.json;
  bad_index["accessors"][3]["count"] = 37;  // indices accessor: more than its view holds
  nlohmann::json cycle = g.json;
  cycle["nodes"][1]["children"] = {0};
  const std::pair<std::string, std::string> cases[] = {
      {make_glb(bad_index, g.bin), "accessor"},
      {make_glb(cycle, g.bin), "node"},
      {std::string("glTF") + good.substr(4, 40), "bad.glb"},
      {"{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"mesh\":0}", "bad.glb"},
  };
  for (const auto& [bytes, needle] : cases) {
    write_text(dir / "bad.glb", bytes);
    const RunResult r = run_ao("bake bad.glb --gltf out.glb" + kRays, dir.path());
    expect_one_line_error(r, needle);
    EXPECT_NE(r.err.find("bad.glb"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out.glb"));
  }
  write_text(dir / "pair.glb", good);
  expect_one_line_error(run_ao("bake pair.glb --gltf out.glb --uv-set 1" + kRays, dir.path()), "pair.glb: has 1 UV set, --uv-set 1 asked for");
  expect_one_line_error(run_ao("bake pair.glb --gltf out.glb --bent-normals b.png" + kRays, dir.path()), "--bent-normals");
  EXPECT_FALSE(fs::exists(dir / "out.glb"));
}

}  // namespace
}  // namespace ao::test
