// SPDX-License-Identifier: Apache-2.0
// Meshes through assimp (OBJ files beyond obj_reader's shape, STL, glTF/GLB), after the checks
// of our own that load_scene_file runs first, and assimp's messages in ao's words. Part of
// load_scene_file (mesh_io.cpp); not installed.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "ao/io/mesh_io.h"

namespace ao::io_detail {

/// Reads `data`, the whole content of `path`, with assimp: the raw meshes are checked (faces
/// without indices, indices out of range, non-finite values; for glTF, node transforms) before
/// post-processing can merge or hide them, then triangulated, welded and converted to a Scene
/// (a glTF that uses a mesh twice keeps instances unless options.flatten_instances), then
/// validate_and_prepare. `is_gltf`: the file is glTF/GLB (check_gltf has passed). Throws
/// InputError "<file>: <problem>" in ao's words (explain_assimp_error), SystemError when memory
/// runs out.
Scene read_with_assimp(const std::filesystem::path& path, std::string_view data, const LoadOptions& options, bool is_gltf);

/// assimp's error message in the user's terms where it is recognised (a table of the messages
/// the mutation campaign met, and the shapes of its glTF reader's messages); otherwise "malformed
/// or truncated file (<assimp's words, one line>)".
std::string explain_assimp_error(std::string_view error);

/// True when assimp's error string is the one it keeps of a std::bad_alloc it caught.
bool assimp_ran_out_of_memory(std::string_view error);

/// "has K UV set(s), --uv-set N asked for": the words of every loader for a UV set the file lacks.
std::string uv_set_error(unsigned sets, int asked);

}  // namespace ao::io_detail
