// SPDX-License-Identifier: Apache-2.0
// PLY (Stanford polygon file) reader of our own: ASCII, binary little- and big-endian, read straight
// into the Mesh arrays. Part of load_scene_file; declared here for the fuzz harness and the tests.
#pragma once

#include <filesystem>
#include <string_view>

#include "ao/scene/mesh.h"

namespace ao {

/// True when `data` starts with the PLY magic line.
bool looks_like_ply(std::string_view data);

/// Reads `data`, the whole content of the PLY file `path`, into a one-mesh Scene (not yet
/// validated): positions from the `vertex` element's x, y, z; normals from nx, ny, nz when all
/// three are present; UVs from u/v, s/t, texture_u/texture_v or texture_s/texture_t; triangles from
/// the `face` element's vertex_indices (or vertex_index) list, polygons fan-triangulated (which
/// assumes convex faces). Other elements and properties are skipped. Keeps the file's vertex count
/// and order. Counts are checked against the file size before anything is allocated, so memory stays
/// within a small multiple of the file size: positions and indices take at most about one byte per
/// byte of data. Throws InputError "<file>: <problem>" for a malformed or truncated header or body,
/// lists with negative or impossible counts, faces of fewer than 3 vertices, indices out of range.
Scene read_ply(const std::filesystem::path& path, std::string_view data);

}  // namespace ao
