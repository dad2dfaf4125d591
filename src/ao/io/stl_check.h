// SPDX-License-Identifier: Apache-2.0
// A structure check of ASCII STL files, run before assimp reads them: assimp 5.2 reads an ASCII
// STL cut off inside a facet as the facets before the cut, without a word (half a mesh, exit 0).
// Part of load_scene_file; declared here for the fuzz harness and the tests.
#pragma once

#include <filesystem>
#include <string_view>

namespace ao {

/// True for data that assimp reads as ASCII STL: it starts with "solid" (after blanks) and its
/// size is not that of a binary STL with the triangle count its header gives (84 + 50 n bytes;
/// binary writers may begin their 80-byte header with "solid" too).
bool is_ascii_stl(std::string_view data);

/// Checks `data`, an ASCII STL (is_ascii_stl), token by token: one or more
/// "solid [name] ... endsolid [name]" blocks, each facet "facet normal x y z outer loop vertex x y z
/// (three times) endloop endfacet", every number a number (number_text.h). Throws InputError
/// "<file>: line N: <problem>" on the first deviation, "truncated" when the file ends inside a
/// facet or a solid.
void check_ascii_stl(const std::filesystem::path& path, std::string_view data);

/// Checks `data`, an STL that is not ASCII (is_ascii_stl false), as binary STL: at least the
/// 84-byte header, and exactly 84 + 50 bytes per triangle the header counts. Throws InputError
/// "<file>: truncated binary STL: ..." or "<file>: binary STL header says N triangles, ...".
void check_binary_stl(const std::filesystem::path& path, std::string_view data);

}  // namespace ao
