// SPDX-License-Identifier: Apache-2.0
// The io layer's one way to word an error: "<file>: <problem>" on one line, with any text quoted
// from a file or a library (assimp, tinygltf, OpenEXR, libpng, nlohmann-json) made printable,
// short and single-line first. Every reader and writer in io/ uses these; not installed.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

namespace ao::io_detail {

/// Throws InputError "<path>: <problem>".
[[noreturn]] void fail(const std::filesystem::path& path, const std::string& problem);

/// A library's message (or a file's text) as one line: line breaks become "; ", tabs spaces and
/// runs of spaces one space, other unprintable bytes '?'; trailing spaces, dots and semicolons
/// are dropped; at most `max_chars` characters of the text are kept, "..." marking a cut.
std::string one_line(std::string_view text, std::size_t max_chars = 200);

/// A token from a file for a message: unprintable bytes '?', at most `max_chars` characters, "..."
/// marking a cut. Text from a hostile file may be anything; the message stays short and readable.
std::string printable(std::string_view token, std::size_t max_chars = 24);

/// printable(token) in single quotes.
std::string quote(std::string_view token);

}  // namespace ao::io_detail
