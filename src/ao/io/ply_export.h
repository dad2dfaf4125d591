// SPDX-License-Identifier: Apache-2.0
// Per-vertex AO as a PLY file that MeshLab and Blender read: binary little-endian, vertices with
// position, normal, 8-bit colour (V as grey, linear) and a float `quality` (V exactly, MeshLab's
// name for a per-vertex scalar), triangles as `vertex_indices`. Written atomically.
#pragma once

#include <filesystem>
#include <vector>

#include "ao/scene/mesh.h"

namespace ao {

/// Writes all meshes of `scene` merged into one PLY; `values` holds one V per vertex in mesh order
/// (as bake_vertices_* return them). Throws InputError when the count does not match.
void write_vertex_ao_ply(const std::filesystem::path& path, const Scene& scene, const std::vector<float>& values);

}  // namespace ao
