// SPDX-License-Identifier: Apache-2.0
// Issue 27, "messages in ao's words": the malformed files the mutation campaign (scripts/mutate)
// meets most, each with the message ao gives. None quotes assimp's or the JSON parser's own text
// ("malformed or truncated file (...)", "[json.exception..."), which names their internals instead of
// what is wrong with the file.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/io/mesh_io.h"
#include "support/bytes.h"
#include "support/run.h"

namespace ao {
namespace {

using nlohmann::json;
using test::TempDir;

/// One triangle with UVs and a material, its buffer a data URI; accessor 0 POSITION, 1 indices,
/// 2 TEXCOORD_0.
json triangle() {
  std::string bytes;
  test::append(bytes, std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0});
  test::append(bytes, std::vector<std::uint16_t>{0, 1, 2, 0});
  test::append(bytes, std::vector<float>{0, 0, 1, 0, 0, 1});
  json j = json::parse(R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
    "materials":[{"pbrMetallicRoughness":{"baseColorFactor":[1,0,0,1]}}],
    "meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":2},"indices":1,"material":0}]}],
    "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":6},{"buffer":0,"byteOffset":44,"byteLength":24}],
    "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
                 {"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"},
                 {"bufferView":2,"componentType":5126,"count":3,"type":"VEC2"}]})");
  j["buffers"] = json::array({{{"byteLength", bytes.size()}, {"uri", "data:application/octet-stream;base64," + test::base64(bytes)}}});
  return j;
}

std::string gltf_with(const std::function<void(json&)>& change) {
  json j = triangle();
  change(j);
  return j.dump();
}

struct Case {
  std::string file, content, message;
};

TEST(LoaderMessages, EachCommonMalformedFileGetsAoWords) {
  const std::string quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n";
  const std::string groups = "o a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\ng one\nf 1 2 3\ng two\nf -4 -3 -1\n";
  const std::vector<Case> cases = {
      // OBJ (assimp 5.2's words in the comments)
      {"line.obj", quad + "f 1/1/1 2", "a face has only 2 corners (a line)"},  // aiMesh::mFaces[0] is a LINE but ...
      {"vertices.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0", "the file has no faces (f lines), only vertices"},  // Mesh contains no faces
      {"normals.obj", quad, "the file has no faces (f lines), only vertices"},  // OBJ: vertex normal index out of range
      {"comment.obj", groups + "l 1 #2\n", "an index of a face, line or point cannot be read (a comment after it?)"},  // OBJ: Invalid face index
      {"short-line.obj", groups + "l 1\n", "a line (l) or face has too few vertices"},  // OBJ: bad vertex index
      {"uv1.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0\nvt 1\nvt 0\nf 1/1 2/2 3/3\n", "a v, vt or vn line has the wrong number of values"},  // OBJ: Invalid number of components
      // STL
      {"garbage.stl", std::string(100, 'x'), "binary STL header says 2021161080 triangles"},  // Failed to determine STL storage representation
      {"tiny.stl", "abc", "truncated binary STL: 3 bytes, its header alone takes 84"},  // File is too small
      // glTF (assimp's glTF reader, and nlohmann-json's parser)
      {"cut.gltf", triangle().dump().substr(0, 120), "truncated glTF JSON: it ends inside a value"},
      {"syntax.gltf", R"({"asset":{"version":"2.0"},"scenes":[}]})", "malformed glTF JSON: unexpected text at byte 38"},
      {"scene.gltf", gltf_with([](json& j) { j["scene"] = 5; }), "scene refers to scene 5, the file has 1"},  // GLTF: No scene
      {"material.gltf", gltf_with([](json& j) { j.erase("materials"); }),
       "mesh 0 primitive 0.material refers to material 0, the file has 0"},  // GLTF: Missing section "materials"
      {"materials.gltf", gltf_with([](json& j) { j["materials"] = 5; }), "glTF.materials is not an array"},  // Member "materials" was not of type "array"
      {"material0.gltf", gltf_with([](json& j) { j["materials"][0] = 3; }), "material 0 is not an object"},  // Object at index 0 in array "materials" ...
      {"pbr.gltf", gltf_with([](json& j) { j["materials"][0]["pbrMetallicRoughness"] = 3; }),
       "material 0.pbrMetallicRoughness is not an object"},  // Member "pbrMetallicRoughness" was not of type "object" when reading materials[0]
      {"nodata.gltf", gltf_with([](json& j) { j["accessors"][2].erase("bufferView"); }), "an accessor has no data"},  // data is null when extracting ...
      {"matrix.gltf", gltf_with([](json& j) { j["nodes"][0]["matrix"] = 5; }), "node 0.matrix is not an array of 16 numbers"},  // Member "matrix" was not of type "array"
      {"scale.gltf", gltf_with([](json& j) { j["nodes"][0]["scale"] = json::array(); }), "node 0.scale is not an array of 3 numbers"},  // (ignored: unscaled)
      {"rotation.gltf", gltf_with([](json& j) { j["nodes"][0]["rotation"] = {0, 0, 0, 0}; }), "node 0.rotation is not a unit quaternion (length 0"},
      {"roots.gltf", gltf_with([](json& j) { j["scenes"][0]["nodes"] = {0, 0}; }), "scene 0 lists node 0 twice"},  // (placed twice)
      {"textures.gltf", gltf_with([](json& j) { j["textures"] = 5; }), "textures is not an array"},  // Member "textures" was not of type "array"
      {"texture0.gltf", gltf_with([](json& j) { j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}}; }),
       "the file refers to its textures but has none"},  // GLTF: Missing section "textures"
      {"texture1.gltf", gltf_with([](json& j) { j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}}, j["textures"] = {3}; }),
       "textures[0] is not an object"},  // Object at index 0 in array "textures" is not a JSON object
  };
  TempDir dir;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    const auto path = dir.write(c.file, c.content);
    try {
      load_scene_file(path);
      ADD_FAILURE() << "loaded";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path.string() + ": ", 0), 0u) << what;
      EXPECT_NE(what.find(c.message), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      for (const char* raw : {"malformed or truncated file (", "json.exception", "aiMesh", "GLTF:", "OBJ:"}) EXPECT_EQ(what.find(raw), std::string::npos) << what;
    }
  }
}

}  // namespace
}  // namespace ao
