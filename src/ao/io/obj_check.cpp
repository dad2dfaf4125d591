// SPDX-License-Identifier: Apache-2.0
// OBJ line scan: numbers and indices, checked before assimp can take NaN UVs or drop UVs.
// assimp resolves positive indices after reading the whole file (so they may point forwards) and
// negative ones against the elements read so far; the scan counts the same way.
#include "ao/io/obj_check.h"

#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>
#include <system_error>

#include "ao/core/error.h"
#include "ao/io/asset_path.h"
#include "ao/io/io_error_internal.h"
#include "ao/io/number_text.h"

namespace ao {
namespace {

namespace fs = std::filesystem;

/// Next whitespace-separated token of `line` from `pos`; empty at the end.
std::string_view next_token(std::string_view line, std::size_t& pos) {
  while (pos < line.size() && std::isspace(static_cast<unsigned char>(line[pos]))) ++pos;
  const std::size_t start = pos;
  while (pos < line.size() && !std::isspace(static_cast<unsigned char>(line[pos]))) ++pos;
  return line.substr(start, pos - start);
}

using io_detail::printable;

struct Lines {
  std::string_view text;
  std::size_t pos = 0;
  long long number = 0;
  /// Next line without its comment and line end; false at the end.
  bool next(std::string_view& line) {
    if (pos >= text.size()) return false;
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    line = text.substr(pos, end - pos);
    pos = end + 1;
    ++number;
    line = line.substr(0, std::min(line.find('#'), line.size()));
    return true;
  }
};

enum Kind { kVertex, kUv, kNormal };
constexpr std::array<const char*, 3> kNames{"vertex", "UV", "normal"};
constexpr std::array<const char*, 3> kPlural{"vertices", "UVs", "normals"};

/// Throws the problem of one line as "<file>: line N: <problem>".
struct LineError {
  const fs::path& path;
  long long line;
  [[noreturn]] void operator()(const std::string& problem) const {
    throw InputError(path.string() + ": line " + std::to_string(line) + ": " + problem);
  }
};

using Counts = std::array<long long, 3>;

/// Pass 1: the file's totals of vertices, UVs and normals, for positive indices.
Counts count_elements(std::string_view data) {
  Counts total{0, 0, 0};
  Lines lines{data};
  std::string_view line;
  while (lines.next(line)) {
    std::size_t pos = 0;
    const std::string_view key = next_token(line, pos);
    if (key == "v") ++total[kVertex];
    else if (key == "vt") ++total[kUv];
    else if (key == "vn") ++total[kNormal];
  }
  return total;
}

/// The numbers of a v, vt or vn line (element `index` of its kind), from `pos`.
void check_numbers(std::string_view line, std::size_t pos, Kind kind, long long index, const LineError& fail) {
  // Vertices and normals have x y z (a vertex may add w or a colour: not checked); UVs u [v [w]].
  const int needed = kind == kUv ? 1 : 3, checked = 3;
  for (int k = 0; k < checked; ++k) {
    std::string_view token = next_token(line, pos);
    if (token.empty()) {
      if (k < needed) fail(std::string(kNames[kind]) + " has " + std::to_string(k) + " numbers, expected " + std::to_string(needed));
      break;
    }
    float value = 0;
    if (!parse_real(token, value)) fail(std::string(kNames[kind]) + " " + std::to_string(index) + ": '" + printable(token) + "' is not a number");
    if (!std::isfinite(value))
      fail(std::string(kNames[kind]) + " " + std::to_string(index) + (kind == kVertex ? " has a non-finite coordinate" : " is not finite") +
           " ('" + printable(token) + "')");
  }
}

/// An mtllib line's library names, from `pos`: the whole rest of the line (a name with spaces) and
/// each word of it must stay inside the asset folder.
void check_mtllib(const fs::path& path, const fs::path& folder, std::string_view line, std::size_t pos, const LineError& fail) {
  std::string_view rest = line.substr(pos);
  const std::size_t first = rest.find_first_not_of(" \t\r");
  rest = first == std::string_view::npos ? std::string_view() : rest.substr(first);
  while (!rest.empty() && std::isspace(static_cast<unsigned char>(rest.back()))) rest.remove_suffix(1);
  try {
    if (!rest.empty()) resolve_asset_reference(path, folder, rest, "material library");
    for (std::string_view name = next_token(line, pos); !name.empty(); name = next_token(line, pos))
      resolve_asset_reference(path, folder, name, "material library");
  } catch (const InputError& e) {
    const std::string what = e.what();
    fail(what.substr(path.string().size() + 2));  // the same words, with the line number
  }
}

/// The corners of an f, l or p line, from `pos`: v, v/vt, v//vn or v/vt/vn, each index in range.
void check_corners(std::string_view line, std::size_t pos, const Counts& total, const Counts& seen, const LineError& fail) {
  for (std::string_view corner = next_token(line, pos); !corner.empty(); corner = next_token(line, pos)) {
    if (corner == "\\") break;  // continued on the next line
    std::size_t start = 0;
    for (int kind = kVertex; kind <= kNormal && start <= corner.size(); ++kind) {
      const std::size_t slash = std::min(corner.find('/', start), corner.size());
      const std::string_view part = corner.substr(start, slash - start);
      start = slash + 1;
      if (part.empty()) {
        if (kind == kVertex) fail("face corner '" + printable(corner) + "' has no vertex index");
        continue;
      }
      long long i = 0;
      const auto [ptr, ec] = std::from_chars(part.data(), part.data() + part.size(), i);
      if (ec != std::errc() || ptr != part.data() + part.size()) fail("'" + printable(corner) + "' is not a face corner (v, v/vt, v//vn or v/vt/vn)");
      if (i == 0) fail(std::string(kNames[kind]) + " index 0 is out of range, OBJ indices start at 1");
      const bool ok = i > 0 ? i <= total[kind] : -i <= seen[kind];
      if (!ok)
        fail(std::string(kNames[kind]) + " index " + std::to_string(i) + " is out of range, the file has " + std::to_string(i > 0 ? total[kind] : seen[kind]) +
             " " + kPlural[kind] + (i > 0 ? "" : " before this line"));
    }
  }
}

}  // namespace

void check_obj(const fs::path& path, std::string_view data, const fs::path& asset_root) {
  const fs::path folder = asset_folder(path, asset_root);
  const Counts total = count_elements(data);
  // Pass 2: numbers and indices; at the end, whether there was anything to draw.
  Counts seen{0, 0, 0};
  bool elements = false;
  Lines lines{data};
  std::string_view line;
  while (lines.next(line)) {
    const LineError fail{path, lines.number};
    std::size_t pos = 0;
    const std::string_view key = next_token(line, pos);
    if (key == "v" || key == "vt" || key == "vn") {
      const Kind kind = key == "v" ? kVertex : key == "vt" ? kUv : kNormal;
      check_numbers(line, pos, kind, seen[kind]++, fail);
    } else if (key == "mtllib") {
      check_mtllib(path, folder, line, pos, fail);
    } else if (key == "f" || key == "l" || key == "p") {
      elements = true;
      check_corners(line, pos, total, seen, fail);
    }
  }
  // assimp makes a point cloud of such a file, or fails with words about normals.
  if (!elements) throw InputError(path.string() + ": the file has no faces (f lines), only vertices");
}

}  // namespace ao
