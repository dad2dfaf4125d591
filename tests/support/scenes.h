// SPDX-License-Identifier: Apache-2.0
// Scenes the tests build from shapes.
#pragma once

#include <utility>
#include <vector>

#include "ao/scene/mesh.h"

namespace ao::test {

/// A validated scene made of `meshes`, named "test".
inline Scene scene_of(std::vector<Mesh> meshes) {
  Scene s;
  s.name = "test";
  s.meshes = std::move(meshes);
  validate_and_prepare(s);
  return s;
}

}  // namespace ao::test
