// SPDX-License-Identifier: Apache-2.0
// A structure check of glTF 2.0 and GLB files, run before assimp reads them, because assimp 5.2
// crashes on or silently misreads hostile ones (see gltf_check.cpp). Part of load_scene_file;
// declared here for the fuzz harness and the tests.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace ao {

/// Deepest JSON nesting (objects and arrays) accepted in a glTF: real files stay below 20.
inline constexpr int kMaxGltfJsonDepth = 128;
/// Longest chain of nodes (root to deepest child) accepted in a glTF scene graph: real skeletons
/// and scene hierarchies stay below a few hundred.
inline constexpr int kMaxGltfNodeDepth = 1024;

/// True for data that starts with the GLB magic "glTF" or, for a name ending in .gltf or .glb or
/// data whose first non-blank character is '{', for what should be read as glTF.
bool looks_like_gltf(const std::filesystem::path& path, std::string_view data);

/// What reading a glTF makes, counted from its JSON before anything is read (accessors may be
/// shared by many meshes and meshes used by many nodes, so a small file can describe a huge scene).
struct GltfSize {
  struct Counts {
    std::uint64_t vertices = 0, triangles = 0;
    std::uint64_t bytes = 0;  ///< assimp's copy of them: 12 bytes per attribute and vertex (colours 16), 48 per triangle.
    void add(const Counts& o) { vertices += o.vertices, triangles += o.triangles, bytes += o.bytes; }
  };
  Counts stored;           ///< Every mesh once (what is read, and what instancing keeps).
  Counts world;            ///< Every mesh once per node that uses it (what flattening makes).
  std::uint64_t uses = 0;  ///< Nodes that use a mesh.
  /// The first primitive whose indices accessor has no bufferView ("mesh 1 primitive 0, indices
  /// accessor 7"): glTF reads its indices as zeros, a primitive without a triangle. The scene
  /// loaders read the file; the document a bake rewrites (gltf_document.h) refuses it. Empty: none.
  std::string indices_without_data;
};

/// Checks `data`, the whole content of `path`, as glTF 2.0 JSON or GLB, without allocating more
/// than a small multiple of its size: GLB chunk lengths against the file size (the chunks must fill
/// the file exactly, JSON first, at most one BIN, second); extensionsRequired (only extensions that
/// leave geometry, transforms, UVs and base colour as ao reads them: KHR_materials_*,
/// KHR_texture_transform, KHR_texture_basisu, EXT_texture_webp, EXT_texture_avif,
/// KHR_lights_punctual, KHR_xmp_json_ld; compressed geometry says so); JSON nesting depth
/// (kMaxGltfJsonDepth); the node graph (indices in range, one parent per node, no cycle, depth at
/// most kMaxGltfNodeDepth); buffers (GLB BIN chunk, base64 data URI or a file beside `path`)
/// against their byteLength; file URIs of buffers and images inside `asset_root` (empty, the
/// default: the folder of `path`; see asset_path.h), after resolving "..", "." and symbolic links; bufferViews and accessors inside their buffers; byteStride at least
/// the element size; POSITION accessors VEC3 float, all attributes of a primitive of one count;
/// index accessors unsigned SCALAR with every index below the primitive's vertex count; sparse
/// accessors in range. Throws InputError "<file>: <what>, <which accessor/node/...>" on the first
/// problem. glTF 1.0 (asset.version 1.x, GLB version 1) is refused. Returns the sizes it counted.
GltfSize check_gltf(const std::filesystem::path& path, std::string_view data, const std::filesystem::path& asset_root = {});

}  // namespace ao
