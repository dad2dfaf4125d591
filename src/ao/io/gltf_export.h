// A scene with its baked AO map as a binary glTF 2.0 (.glb) that any glTF viewer opens: one mesh
// per scene mesh (positions, normals, TEXCOORD_0, uint32 indices), each with a material whose
// occlusionTexture is the map (embedded PNG, red channel = V, per the glTF spec). The material is
// fresh (baseColorFactor = the mesh's albedo) or, when the input was glTF, the input's material
// (read by load_gltf_materials) with the occlusion texture added. Written atomically.
#pragma once

#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "ao/scene/mesh.h"

namespace ao {

/// A texture reference of a source glTF material.
struct GltfTextureRef {
  int image = -1;         ///< Index into GltfSource::images.
  int uv_set = 0;         ///< The source's TEXCOORD_n it is mapped with.
  float scale = 1.0f;     ///< normalTexture.scale.
  int wrap_s = 10497, wrap_t = 10497;  ///< glTF sampler wrap modes (10497 REPEAT, 33071 CLAMP, 33648 MIRRORED).
  int mag_filter = 0, min_filter = 0;  ///< glTF sampler filters; 0 = not given.
};

/// The properties of a source glTF material that matter for viewing it.
struct GltfMaterialInfo {
  std::string name;
  std::array<float, 4> base_color{1, 1, 1, 1};
  float metallic = 1.0f, roughness = 1.0f;
  std::array<float, 3> emissive{0, 0, 0};
  float emissive_strength = 1.0f;  ///< KHR_materials_emissive_strength.
  std::string alpha_mode = "OPAQUE";
  float alpha_cutoff = 0.5f;
  bool double_sided = false;
  bool unlit = false;  ///< KHR_materials_unlit.
  std::optional<GltfTextureRef> base_color_texture, metallic_roughness_texture, normal_texture, emissive_texture;
};

struct GltfImage {
  std::string bytes;      ///< Encoded file (PNG or JPEG).
  std::string mime_type;  ///< "image/png" or "image/jpeg".
};

/// What a glTF input contributes to the exported file, per mesh of the loaded Scene.
struct GltfSource {
  std::vector<std::optional<GltfMaterialInfo>> materials;  ///< Per scene mesh; nullopt: a fresh material is written.
  /// Per scene mesh: the source UV sets (other than the baked one, which is Mesh::uvs) that its
  /// material's textures use, in the loader's convention (v up).
  std::vector<std::map<int, std::vector<Vec2>>> uv_sets;
  std::vector<GltfImage> images;
  std::vector<std::string> warnings;  ///< Things not carried over (unsupported image types, unreadable files, ...).
};

/// True for .gltf/.glb files (by extension, or a GLB's magic).
bool is_gltf_file(const std::filesystem::path& path);

/// Reads the materials of the glTF/GLB file `path` that `scene` was loaded from (load_scene_file
/// with UV set `uv_set`): factors, emissive, alphaMode/cutoff, doubleSided, name, unlit, and the
/// base colour, metallic-roughness, normal and emissive textures (images copied, external files
/// included). The file's own occlusion texture is not kept (the baked map replaces it). Meshes
/// are matched to the scene's in load order by name and vertex count; an unmatched mesh gets a
/// warning and a fresh material. Throws InputError when assimp cannot read the file.
GltfSource load_gltf_materials(const std::filesystem::path& path, const Scene& scene, int uv_set = 0);

/// `png` holds the encoded PNG bytes of the AO map; meshes without UVs are written without
/// TEXCOORD_0 and without the occlusion texture. UVs are converted from the loader's OpenGL
/// convention (v up) to glTF's (v down). The baked UV set (Mesh::uvs) is always TEXCOORD_0 and the
/// occlusion texture's texCoord is 0; with `source`, other UV sets its textures use follow as
/// TEXCOORD_1.. (in source order) and their texCoord is remapped.
/// With `vertex_ao` (V per vertex of every mesh, concatenated in mesh order, as the per-vertex
/// bakers return it), each primitive also gets COLOR_0 = (V, V, V) as float VEC3; an empty `png`
/// then writes no occlusion texture. A count other than the scene's vertex count is an InputError.
void write_ao_glb(const std::filesystem::path& path, const Scene& scene, const std::string& png, const GltfSource* source = nullptr,
                  const std::vector<float>* vertex_ao = nullptr);

}  // namespace ao
