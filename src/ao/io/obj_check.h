// SPDX-License-Identifier: Apache-2.0
// A line scan of Wavefront OBJ files, run before assimp reads them, because assimp 5.2 takes
// `vt nan` as a UV and drops every UV of a file that has one out-of-range UV index, without a word.
// Part of load_scene_file; declared here for the fuzz harness and the tests.
#pragma once

#include <filesystem>
#include <string_view>

namespace ao {

/// Checks `data`, the whole content of the OBJ `path`: the numbers of `v`, `vt` and `vn` lines
/// parse and are finite (vertices need 3, UVs 1 to 3, normals 3), and every index of `f`, `l` and
/// `p` lines (vertex/uv/normal, 1-based, or negative = relative to the end of the list so far) is
/// nonzero and refers to an element the file has. Throws InputError "<file>: line N: <problem>".
/// A line ending in '\' continues on the next (the OBJ convention). A material library (`mtllib`,
/// its whole name and each word of it) must lie inside `asset_root` (empty, the default: the
/// folder of `path`; asset_path.h): "<file>: line N: material library '<name>' lies outside ...".
void check_obj(const std::filesystem::path& path, std::string_view data, const std::filesystem::path& asset_root = {});

}  // namespace ao
