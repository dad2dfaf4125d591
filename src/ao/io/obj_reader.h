// SPDX-License-Identifier: Apache-2.0
// A fast reader for the Wavefront OBJ files that hold one mesh (scans, exports of one object: the
// meshes that are big), loading them as assimp 5.2 plus ao's post-processing did, at a fraction of
// its time (BENCHMARKS.md, "Loading"). Anything beyond that shape returns no scene, and the caller
// reads the file as before (check_obj, then assimp), so every other file, and every bad one, keeps
// the result and the message it had. Part of load_scene_file; declared here for the tests.
#pragma once

#include <filesystem>
#include <optional>
#include <string_view>

#include "ao/io/mesh_io.h"

namespace ao {

/// Reads `data`, the whole content of the OBJ `path`, when it is one mesh: only `v` (x y z), `vt`
/// (u v [w]), `vn` (x y z), `f` with 3 or 4 corners all of one form (v, v/vt, v//vn or v/vt/vn;
/// indices 1-based, negative relative to the end), `s`, comments and blank lines, plus before the
/// first face at most one `o` or `g` line with one name, `mtllib` lines and at most one `usemtl`
/// whose material the library defines with a `Kd` colour. The result is what load_scene_file made
/// of such a file through assimp: one Mesh named after the `o`/`g` line ("defaultobject" without
/// one), albedo Kd (Mesh's default without `usemtl`), vertices welded where position, UV and
/// normal are all equal, numbered in the order the faces first use them, quads split as assimp's
/// Triangulate splits them (along the diagonal from a concave corner, else from corner 0), then
/// validate_and_prepare. Returns nullopt, having thrown nothing, for every other file: other
/// keywords, more objects or materials, n-gons, lines, points, vertex colours, a number or an
/// index that is not valid. Throws InputError for a material library outside the asset's folder
/// (asset_path.h), a `--uv-set` above 0, and what validate_and_prepare refuses.
std::optional<Scene> read_simple_obj(const std::filesystem::path& path, std::string_view data, const LoadOptions& options);

}  // namespace ao
