// SPDX-License-Identifier: Apache-2.0
// The scene of a file that holds one mesh (OFF, and OBJ on its fast path): named after the file,
// validated and prepared for tracing as every loader's scene is.
#pragma once

#include <filesystem>
#include <utility>

#include "ao/scene/mesh.h"

namespace ao::io_detail {

inline Scene one_mesh_scene(const std::filesystem::path& path, Mesh mesh) {
  Scene scene;
  scene.name = path.filename().string();
  scene.meshes.push_back(std::move(mesh));
  validate_and_prepare(scene);
  return scene;
}

}  // namespace ao::io_detail
