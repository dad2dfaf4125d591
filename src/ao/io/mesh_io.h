// SPDX-License-Identifier: Apache-2.0
// Mesh files -> Scene. OFF, PLY and one-mesh OBJ files are read by our own strict readers; other
// OBJ files, STL and glTF/GLB go through assimp, after checks of our own (see assimp_reader.cpp for why).
#pragma once

#include <filesystem>

#include "ao/scene/mesh.h"

namespace ao {

struct LoadOptions {
  /// Which UV set (assimp channel = glTF TEXCOORD_n, in the file's order) becomes Mesh::uvs. 0, the
  /// default, is the first set; a mesh lacking the set loads without UVs. Asking for a set above 0
  /// that no mesh of the file has is an InputError "<file>: has K UV sets, --uv-set N asked for".
  int uv_set = 0;
  /// glTF only: a mesh that the node tree uses several times is copied into world space once per
  /// use (assimp's pre-transform, which also joins meshes sharing a material) instead of being
  /// kept once with one Scene::instances entry per use. On for baking, whose maps and per-vertex
  /// values belong to each placed copy; off (instances) by default.
  bool flatten_instances = false;
  /// The folder that the files a model references (a glTF's external buffers and images, an OBJ's
  /// material libraries) must lie in, after resolving "..", "." and symbolic links; a reference
  /// outside it is an InputError naming it (asset_path.h). Empty, the default: the model's own folder.
  std::filesystem::path asset_root;
};

/// Loads OBJ, PLY, OFF, STL, glTF/GLB (by content/extension; OBJ, STL and glTF via assimp) into a
/// Scene: one Mesh per assimp mesh (so per material; one for OFF and PLY), triangulated, with normals when the file has them, the UV set
/// `options.uv_set` (default the first), and the material's diffuse colour (or glTF baseColorFactor) as albedo. Node transforms are applied
/// (pre-transform vertices), except that a glTF whose node tree uses a mesh more than once keeps
/// that mesh once in object space with one Scene::instances entry per node using it (named after
/// the node; see LoadOptions::flatten_instances); its other meshes are moved to world space one by one. Calls validate_and_prepare. Throws InputError with one line naming the
/// file and problem: missing/unreadable file, unknown format, truncated/malformed content, bad counts,
/// NaN/inf, coordinates beyond kMaxCoordinate, indices out of range, empty scene, and what
/// check_gltf (gltf_check.h) and check_obj (obj_check.h) refuse. Throws SystemError when memory
/// runs out reading a PLY whose counts the file does hold.
///
/// Details: OFF and PLY keep the file's vertex count and order (faces of n > 3 vertices are fan-triangulated,
/// which assumes convex faces); OFF, PLY and STL have no materials, so their albedo is the Mesh default
/// 0.8, as is that of assimp's stand-in "DefaultMaterial" (an OBJ without .mtl); STL facet normals are
/// discarded so the triangle soup can be welded into a connected mesh with smooth normals.
/// Scene::name is the file name without its folder; Mesh::name is the file's mesh name (the file stem
/// for OFF and PLY). The file's cameras are not read.
Scene load_scene_file(const std::filesystem::path& path, const LoadOptions& options = {});

}  // namespace ao
