// A scene with its baked AO map as a binary glTF 2.0 (.glb) that any glTF viewer opens: one mesh
// per scene mesh (positions, normals, TEXCOORD_0, uint32 indices), each with a material whose
// occlusionTexture is the map (embedded PNG, red channel = V, per the glTF spec), and whose
// baseColorFactor is the mesh's albedo. Written atomically.
#pragma once

#include <filesystem>
#include <string>

#include "ao/scene/mesh.h"

namespace ao {

/// `png` holds the encoded PNG bytes of the AO map; meshes without UVs are written without
/// TEXCOORD_0 and without the occlusion texture. UVs are converted from the loader's OpenGL
/// convention (v up) to glTF's (v down).
void write_ao_glb(const std::filesystem::path& path, const Scene& scene, const std::string& png);

}  // namespace ao
