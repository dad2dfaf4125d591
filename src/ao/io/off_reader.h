// SPDX-License-Identifier: Apache-2.0
// OFF (Geomview object file format) reader of our own: text OFF, COFF, NOFF and CNOFF, read
// straight into the Mesh arrays. Part of load_scene_file; declared here for the fuzz harness and
// the tests.
#pragma once

#include <filesystem>
#include <string_view>

#include "ao/scene/mesh.h"

namespace ao {

/// True when `data` starts (after blank space) with an OFF keyword ([C][N][ST][4][n]OFF).
bool looks_like_off(std::string_view data);

/// Reads `data`, the whole content of the OFF file `path`, into a one-mesh Scene named after the
/// file, then validate_and_prepare: positions, normals for NOFF and CNOFF (a colour after them is
/// ignored), faces fan-triangulated (which assumes convex faces). Keeps the file's vertex count and
/// order. The header's counts are checked against the file size before anything is allocated, and
/// the body must hold exactly the faces the header says. Throws InputError "<file>: <problem>" for
/// another OFF variant (binary, ST, 4D, nD), a malformed or truncated header or body, non-finite
/// numbers, faces of fewer than 3 vertices, indices out of range, and what validate_and_prepare
/// refuses.
Scene read_off(const std::filesystem::path& path, std::string_view data);

}  // namespace ao
