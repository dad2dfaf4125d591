// SPDX-License-Identifier: Apache-2.0
// A glTF 2.0 document kept whole for `ao bake`'s round trip: load it (tinygltf, after check_gltf),
// hand out world-space scenes to bake, add the baked maps (one image and texture per baked mesh,
// an occlusionTexture on the materials of its primitives) or per-vertex AO (COLOR_0), and save the
// same document as GLB. Nodes, names, hierarchy, instancing, animations, skins, cameras, extensions,
// extras and untouched materials pass through; images stay encoded (never decoded or re-encoded).
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "ao/scene/mesh.h"

namespace ao {

/// The scene of a document in world space, every instance of every mesh (depth first from the
/// displayed scene's roots, children in order), one Mesh per triangle primitive and instance.
struct GltfWorldScene {
  /// Where a Mesh of `scene` comes from.
  struct Source {
    int mesh = -1;                ///< glTF mesh index.
    int primitive = -1;           ///< Primitive index within that mesh.
    int node = -1;                ///< The node instancing it.
    bool first_instance = false;  ///< The first node (in that order) that uses the mesh.
  };
  Scene scene;                  ///< Validated (validate_and_prepare); meshes left without triangles are gone.
  std::vector<Source> sources;  ///< One per scene.meshes entry.
};

/// A loaded glTF/GLB document. Move-only.
class GltfDocument {
 public:
  /// Reads `path` (glTF with its buffers and images beside it, or GLB): check_gltf first, then
  /// tinygltf, which may read only files in `asset_root` (empty, the default: the folder of
  /// `path`) or below it, and writes nothing; a buffer or image URI that leaves that folder is an
  /// InputError (asset_path.h).
  /// Buffers are merged into one (the GLB's binary chunk), and images given by URI (data: or a
  /// file in that folder) are moved into it still encoded; an image file that cannot be read keeps
  /// its URI, with a warning. `uv_set` is the TEXCOORD_n baked into. Throws InputError "<file>: <problem>"
  /// for what check_gltf refuses, what tinygltf cannot parse, geometry compressed with
  /// KHR_draco_mesh_compression or EXT_meshopt_compression, primitives whose accessors cannot be read, a `uv_set` above 0 that no primitive has ("has K UV sets, --uv-set N asked for"),
  /// and a document with no triangles in its scene.
  GltfDocument(const std::filesystem::path& path, int uv_set, const std::filesystem::path& asset_root = {});
  ~GltfDocument();
  GltfDocument(GltfDocument&&) noexcept;
  GltfDocument& operator=(GltfDocument&&) noexcept;

  /// Things the load could not carry over (unreadable image files, ...), one line each.
  const std::vector<std::string>& warnings() const;

  /// glTF meshes with at least one instance in the displayed scene and a triangle primitive, in
  /// the file's order; `with_uv_set`: only those with a triangle primitive that has TEXCOORD_<uv_set>.
  std::vector<int> instanced_meshes(bool with_uv_set) const;
  /// "'name'" or "mesh N" for messages.
  std::string mesh_label(int mesh) const;
  /// Nodes of the displayed scene that use the mesh.
  int instance_count(int mesh) const;
  /// Triangles and vertices of every instance of every mesh, what a world scene holds: up to the
  /// file's vertices times its nodes, so check them before world_scene (ao bake estimates the
  /// memory of their BVH and refuses a run that does not fit).
  std::size_t world_triangle_count() const;
  std::size_t world_vertex_count() const;

  /// The scene to bake `baked_mesh` with: every instance of every mesh in world space; only the
  /// primitives of `baked_mesh`'s first instance that have TEXCOORD_<uv_set> keep it (as
  /// Mesh::uvs, v up), so they are the ones baked and everything else occludes. `baked_mesh` -1:
  /// no UVs anywhere (per-vertex AO). Node transforms are applied (matrix or TRS, doubles), normals
  /// by the inverse transpose; a mirroring transform reverses the winding, as glTF specifies.
  /// Skins and morph targets are not applied (the bind pose). Throws InputError for what
  /// validate_and_prepare refuses.
  GltfWorldScene world_scene(int baked_mesh) const;

  /// Adds `png` (an encoded PNG) as the AO map of `mesh`: one image (in the binary chunk), one
  /// texture, and, at save, an occlusionTexture (texCoord = uv_set, strength 1) on the material of
  /// every triangle primitive of the mesh that has TEXCOORD_<uv_set>. A material also used by
  /// primitives that get another map or none is cloned for this mesh's primitives; a primitive
  /// without a material gets a fresh default one. An occlusionTexture the material had is
  /// replaced (with a warning at save).
  void add_occlusion_map(int mesh, const std::string& png);

  /// Sets COLOR_0 = (V, V, V) (float VEC3) of primitive `primitive` of `mesh`; `ao` has one V per
  /// vertex of its POSITION accessor. A COLOR_0 the primitive had is replaced (with a warning at save).
  void set_vertex_ao(int mesh, int primitive, const std::vector<float>& ao);

  /// Writes the document as GLB to `path`, atomically; the materials are assigned their maps at
  /// the first save that has maps (add_occlusion_map after that is a logic error). Returns the warnings of the save (replaced
  /// occlusion textures and colours), one line each. Throws SystemError when the file cannot be
  /// written, InputError when the binary chunk would exceed GLB's 4 GB.
  std::vector<std::string> save_glb(const std::filesystem::path& path);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ao
