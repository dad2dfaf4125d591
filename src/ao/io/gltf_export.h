// SPDX-License-Identifier: Apache-2.0
// A scene with its baked AO map as a binary glTF 2.0 (.glb) that any glTF viewer opens: one mesh
// per scene mesh (positions, normals, TEXCOORD_0, uint32 indices), each with a fresh material
// (baseColorFactor = the mesh's albedo) whose occlusionTexture is the map (embedded PNG, red
// channel = V, per the glTF spec). Written atomically. A glTF input is not written through here:
// `ao bake` round-trips it with its nodes, materials and instancing (gltf_document.h).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "ao/scene/mesh.h"

namespace ao {

/// True for .gltf/.glb files (by extension, or a GLB's magic).
bool is_gltf_file(const std::filesystem::path& path);

/// `png` holds the encoded PNG bytes of the AO map; meshes without UVs are written without
/// TEXCOORD_0 and without the occlusion texture. UVs are converted from the loader's OpenGL
/// convention (v up) to glTF's (v down); the baked UV set (Mesh::uvs) is TEXCOORD_0.
/// With `vertex_ao` (V per vertex of every mesh, concatenated in mesh order, as the per-vertex
/// bakers return it), each primitive also gets COLOR_0 = (V, V, V) as float VEC3; an empty `png`
/// then writes no occlusion texture. A count other than the scene's vertex count is an InputError.
void write_ao_glb(const std::filesystem::path& path, const Scene& scene, const std::string& png, const std::vector<float>* vertex_ao = nullptr);

}  // namespace ao
