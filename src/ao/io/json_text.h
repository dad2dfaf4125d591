// SPDX-License-Identifier: Apache-2.0
// JSON from users' files and options (camera files, parameter files, `-p key=value` values,
// sweep values), parsed with limits: a depth limit checked while parsing (nlohmann-json's
// parser is iterative, but copying, printing or comparing a value recurses, so a value nested
// 100,000 deep ends the process on a stack overflow) and a size limit on files. Errors are one
// line naming the source and the place, and never quote the value itself.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include <nlohmann/json.hpp>

namespace ao {

/// Deepest nesting of arrays and objects accepted (a value at top level is depth 1): ao's own
/// JSON (cameras, parameters, summaries) nests at most 4 deep.
inline constexpr int kMaxJsonDepth = 64;

/// Largest JSON file read, bytes (16 MiB): a camera or a parameter file is a few hundred bytes.
inline constexpr std::uintmax_t kMaxJsonFileBytes = std::uintmax_t{16} << 20;

/// Thrown by parse_json_with_depth_limit for a text nested deeper than its limit.
struct JsonTooDeep : std::runtime_error {
  JsonTooDeep() : std::runtime_error("JSON nests too deep") {}
};

/// Thrown by parse_json_with_depth_limit for an object that has a key twice: JSON leaves open
/// which one counts, and readers differ (nlohmann keeps the last, assimp's glTF reader the first),
/// so a checked value could differ from the one another reader then uses. `key` is the key, cut
/// to 40 characters.
struct JsonDuplicateKey : std::runtime_error {
  explicit JsonDuplicateKey(std::string k) : std::runtime_error("JSON has a key twice"), key(std::move(k)) {}
  std::string key;
};

/// `text` parsed as one JSON value, in time linear in its length, refusing nesting deeper than
/// `max_depth` (JsonTooDeep) before the deeper levels are built and an object with a key twice
/// (JsonDuplicateKey); a text that is not JSON throws
/// what nlohmann::json::parse throws (parse_error, with the byte where it stopped). nlohmann's
/// own depth hook, the callback parser, rescans a container after each object in it: quadratic,
/// 2 minutes for a glTF of 200,000 nodes.
nlohmann::json parse_json_with_depth_limit(std::string_view text, int max_depth);

/// `text` parsed as one JSON value, or nullopt when it is not one (invalid or trailing text).
/// InputError "<source>: JSON nests deeper than 64 levels" when it nests deeper than
/// kMaxJsonDepth, found before the deeper levels are built; InputError "<source>: JSON has the
/// key '<key>' twice in one object" for a duplicate key.
std::optional<nlohmann::json> parse_json_limited(std::string_view text, const std::string& source);

/// The JSON file `path` parsed (parse_json_limited). InputError, one line naming the file:
/// "cannot open", "is larger than 16 MiB", "is not valid JSON (line L, column C; expected
/// <expected>)", too deep. `expected` says what the file should hold ("a camera: eye, target, up,
/// fov").
nlohmann::json read_json_file(const std::filesystem::path& path, std::string_view expected);

/// A value for a message: its JSON text, cut after `max_chars` characters with "...", on one line.
std::string json_excerpt(const nlohmann::json& value, std::size_t max_chars = 40);

}  // namespace ao
