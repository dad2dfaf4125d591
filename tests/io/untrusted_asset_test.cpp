// SPDX-License-Identifier: Apache-2.0
// Issue 27, "inputs stay inside their asset": a model's references (glTF buffers and images)
// resolve only inside the model's folder or the folder LoadOptions::asset_root names; anything
// else is one InputError line, and nothing of the file outside appears in any output.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/io/gltf_check.h"
#include "ao/io/gltf_document.h"
#include "ao/io/mesh_io.h"
#include "support/bytes.h"
#include "support/run.h"

namespace ao {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::TempDir;

/// Bytes that would betray the outside file if they reached an output.
const std::string kMarker = "SECRET-OUTSIDE-THE-ASSET-7f3a";

/// A one-triangle buffer with UVs (positions, UVs, uint16 indices), then kMarker.
std::string triangle_buffer() {
  std::string bytes;
  test::append(bytes, std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0});
  test::append(bytes, std::vector<float>{0, 0, 1, 0, 0, 1});
  test::append(bytes, std::vector<std::uint16_t>{0, 1, 2, 0});
  return bytes + kMarker;
}

/// A glTF of one triangle with TEXCOORD_0 whose buffer is the file `uri`.
json gltf_with_buffer_uri(const std::string& uri) {
  json j = json::parse(R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
    "meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1},"indices":2}]}],
    "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":24},
                   {"buffer":0,"byteOffset":60,"byteLength":6}],
    "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
                 {"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"},
                 {"bufferView":2,"componentType":5123,"count":3,"type":"SCALAR"}]})");
  j["buffers"] = json::array({{{"byteLength", triangle_buffer().size()}, {"uri", uri}}});
  return j;
}

std::string file_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Every regular file under `dir` except `except`, as paths.
std::vector<fs::path> files_under(const fs::path& dir, const fs::path& except) {
  std::vector<fs::path> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && !fs::equivalent(e.path(), except)) out.push_back(e.path());
  return out;
}

/// The layout of the tests: <tmp>/secret.bin outside, <tmp>/asset/deep/model.gltf inside.
struct Layout {
  TempDir dir;
  fs::path secret, folder, model;
  explicit Layout(const std::string& uri) {
    secret = dir.write("secret.bin", triangle_buffer());
    folder = dir / "asset" / "deep";
    fs::create_directories(folder);
    model = folder / "model.gltf";
    test::write_text(model, gltf_with_buffer_uri(uri).dump());
  }
};

std::string input_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

TEST(UntrustedAsset, BufferClimbingOutOfTheFolderIsRefusedByEveryReader) {
  const Layout l("../../secret.bin");
  for (const std::string& msg : {input_error([&] { load_scene_file(l.model); }),
                                 input_error([&] { load_scene_file(l.model, {.flatten_instances = true}); }),
                                 input_error([&] { GltfDocument(l.model, 0); })}) {
    EXPECT_NE(msg.find("model.gltf: buffer 0: its file '../../secret.bin' lies outside the asset's folder"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

TEST(UntrustedAsset, AbsolutePathsAndSymbolicLinksOutOfTheFolderAreRefused) {
  const Layout absolute(fs::absolute(TempDir().path()).string());  // any absolute path outside
  EXPECT_NE(input_error([&] { load_scene_file(absolute.model); }).find("lies outside the asset's folder"), std::string::npos);
  const Layout linked("link.bin");
  fs::create_symlink(linked.secret, linked.folder / "link.bin");
  EXPECT_NE(input_error([&] { load_scene_file(linked.model); }).find("'link.bin' lies outside the asset's folder"), std::string::npos);
  EXPECT_NE(input_error([&] { GltfDocument(linked.model, 0); }).find("'link.bin' lies outside the asset's folder"), std::string::npos);
}

TEST(UntrustedAsset, ImageUrisAreHeldToTheSameFolder) {
  const Layout l("buffer.bin");
  test::write_text(l.folder / "buffer.bin", triangle_buffer());
  json j = gltf_with_buffer_uri("buffer.bin");
  j["images"] = json::array({{{"uri", "../../secret.bin"}}});
  test::write_text(l.model, j.dump());
  const std::string msg = input_error([&] { load_scene_file(l.model); });
  EXPECT_NE(msg.find("image 0: its file '../../secret.bin' lies outside the asset's folder"), std::string::npos) << msg;
  EXPECT_NE(input_error([&] { GltfDocument(l.model, 0); }).find("image 0"), std::string::npos);
}

TEST(UntrustedAsset, FilesInsideTheFolderOrANamedRootLoad) {
  const Layout inside("sub/../buffer.bin");  // ".." that stays inside is fine
  test::write_text(inside.folder / "buffer.bin", triangle_buffer());
  fs::create_directory(inside.folder / "sub");
  EXPECT_EQ(load_scene_file(inside.model).triangle_count(), 1u);
  EXPECT_EQ(GltfDocument(inside.model, 0).world_triangle_count(), 1u);
  // A folder the user names widens what the asset may reference.
  const Layout l("../../secret.bin");
  EXPECT_EQ(load_scene_file(l.model, {.asset_root = l.dir.path()}).triangle_count(), 1u);
  EXPECT_EQ(GltfDocument(l.model, 0, l.dir.path()).world_triangle_count(), 1u);
}

TEST(UntrustedAsset, TheCliRefusesAndNoOutputHoldsTheOutsideFile) {
  const Layout l("../../secret.bin");
  const fs::path cwd = l.folder;
  const std::vector<std::string> commands = {
      "render model.gltf -o out.png --width 16 --height 16 --spp 4 -q",
      "bake model.gltf --gltf out.glb -s 16 --spp 4 -q",
      "bake model.gltf -o map.png -s 16 --spp 4 -q",
  };
  for (const std::string& c : commands) {
    SCOPED_TRACE(c);
    const test::RunResult r = test::run_ao(c, cwd);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("lies outside the asset's folder"), std::string::npos) << r.err;
  }
  const std::vector<fs::path> files = files_under(l.dir.path(), l.secret);
  EXPECT_EQ(files, std::vector<fs::path>{l.model}) << "a command wrote a file";
  for (const fs::path& f : files) EXPECT_EQ(file_bytes(f).find(kMarker), std::string::npos) << f;
}

}  // namespace
}  // namespace ao
