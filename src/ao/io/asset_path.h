// SPDX-License-Identifier: Apache-2.0
// Where an asset's own references may point: a glTF's external buffers and images, an OBJ's
// material libraries. A model is untrusted input (a farm bakes assets nobody has looked at), and a
// reference that climbs out of its folder ("../../home/x/.ssh/id_rsa", "/etc/passwd") would carry a
// worker's files into a deliverable (a baked GLB embeds its buffers and images). So a reference
// is followed only when it resolves, after ".", ".." and symbolic links, inside the asset's folder.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace ao {

/// `p` made absolute, with ".", ".." and symbolic links resolved as far as the path exists
/// (fs::weakly_canonical; lexically normalised when that fails).
std::filesystem::path resolved_path(const std::filesystem::path& p);

/// The folder the references of `model` must stay inside, absolute and with symbolic links
/// resolved: `root` when it is not empty (LoadOptions::asset_root), else the folder of `model`.
std::filesystem::path asset_folder(const std::filesystem::path& model, const std::filesystem::path& root = {});

/// True when `file` (any path) resolves, after ".", ".." and symbolic links, to `folder` or a
/// path below it. `folder` as asset_folder returns it.
bool inside_folder(const std::filesystem::path& file, const std::filesystem::path& folder);

/// A glTF URI's percent-encoded octets decoded (RFC 3986, as glTF requires URIs to be written):
/// "m%2Ebin" is the file "m.bin". A '%' not followed by two hex digits stays as it is.
std::string percent_decode(std::string_view uri);

/// The file a reference of `model` names: `reference` (a relative path, or an absolute one) taken
/// from the folder of `model`. InputError "<model>: <what> '<reference>' lies outside the asset's
/// folder '<folder>'; an asset may reference files only in its own folder or below it" when it
/// does not resolve inside `folder`. Whether the file exists is the caller's check.
std::filesystem::path resolve_asset_reference(const std::filesystem::path& model, const std::filesystem::path& folder,
                                              std::string_view reference, const std::string& what);

}  // namespace ao
