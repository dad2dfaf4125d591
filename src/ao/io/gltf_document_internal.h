// SPDX-License-Identifier: Apache-2.0
// The parts of GltfDocument (gltf_document.h) that work on tinygltf's model by themselves: reading
// a primitive's accessors into a Mesh (gltf_primitive.cpp) and putting the baked maps on the
// materials (gltf_materials.cpp). Not installed; hidden, as the tinygltf types they take.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "ao/io/tiny_gltf_internal.h"
#include "ao/scene/mesh.h"

#pragma GCC visibility push(hidden)

namespace ao::io_detail {

/// True when the primitive draws triangles (TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN; no mode
/// means TRIANGLES).
inline bool gltf_is_triangles(const tinygltf::Primitive& p) {
  return p.mode == -1 || (p.mode >= TINYGLTF_MODE_TRIANGLES && p.mode <= TINYGLTF_MODE_TRIANGLE_FAN);
}

/// "'name'" or "mesh N", for messages.
std::string gltf_mesh_label(const tinygltf::Model& model, int mesh);

/// The mesh's name, or "mesh N", for the names of what is added for it.
std::string gltf_plain_name(const tinygltf::Model& model, int mesh);

/// Primitive `prim` of mesh `mesh` of the document `path` as a Mesh in the mesh's own space:
/// positions, normals (when given), the UV set `uv_attribute` ("TEXCOORD_n"; empty: none) when
/// given, v flipped to the loader's v-up convention, and triangle indices (strips and fans
/// triangulated as the spec orders them). Every accessor read is bounds-checked against its
/// bufferView and buffer; InputError "<file>: mesh M primitive P ...: <problem>" otherwise.
Mesh read_gltf_primitive(const tinygltf::Model& model, const std::filesystem::path& path, int mesh, int prim, const std::string& uv_attribute);

/// Puts the AO map texture `map_texture[mesh]` as the occlusionTexture (texCoord `uv_set`, strength
/// 1) on the material of every triangle primitive of that mesh that has TEXCOORD_<uv_set>: in
/// place when the material serves only such primitives (or is the first map of a material every
/// user needs changed), else on a clone for this mesh; a fresh default material for a primitive
/// without one. Appends a warning per material whose occlusion texture was replaced.
void assign_occlusion_maps(tinygltf::Model& model, const std::map<int, int>& map_texture, int uv_set, std::vector<std::string>& warnings);

}  // namespace ao::io_detail

#pragma GCC visibility pop
