// SPDX-License-Identifier: Apache-2.0
// OFF (Geomview): [C][N]OFF, counts "vertices faces [edges]", one vertex per line (x y z, then
// nx ny nz for N, then a colour we ignore), one face per line ("n i0 ... in-1", then an ignored
// colour). '#' starts a comment. Our own reader rather than assimp's, which (libassimp 5.2.5)
// loads a face index past the vertex list without complaint, allocates 7.8 GB for a header
// claiming 4e8 vertices, fails a file cut in the face list with "aiMesh::mFaces[2258].mIndices is
// nullptr", and welds vertices so that counts stop matching the header.
#include "ao/io/off_reader.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <system_error>
#include <type_traits>
#include <vector>

#include "ao/io/io_error_internal.h"
#include "ao/io/one_mesh_scene_internal.h"
#include "ao/io/number_text.h"

namespace ao {
namespace {

namespace fs = std::filesystem;
using io_detail::fail;
using io_detail::quote;

/// Splits text into lines with '#' comments removed, remembering 1-based line numbers for messages.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}

  /// Next line that has a token, with comments stripped; false at the end of the text.
  bool next(std::string_view& line) {
    while (pos_ < text_.size()) {
      const std::size_t end = std::min(text_.find('\n', pos_), text_.size());
      std::string_view l = text_.substr(pos_, end - pos_);
      pos_ = end + 1;
      ++line_number_;
      l = l.substr(0, std::min(l.find('#'), l.size()));
      if (l.find_first_not_of(" \t\r\f\v") != std::string_view::npos) {
        line = l;
        return true;
      }
    }
    return false;
  }
  int line_number() const { return line_number_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  int line_number_ = 0;
};

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const std::size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
  return tokens;
}

template <class T>
bool parse_number(std::string_view token, T& value) {
  const char* first = token.data();
  const char* last = first + token.size();
  if constexpr (std::is_floating_point_v<T>) {
    if (first != last && *first == '+') ++first;  // from_chars rejects a leading '+', some writers emit it
  }
  const auto [ptr, ec] = std::from_chars(first, last, value);
  return ec == std::errc() && ptr == last;
}

}  // namespace

bool looks_like_off(std::string_view data) {
  const std::size_t start = data.find_first_not_of(" \t\r\n");
  if (start == std::string_view::npos) return false;
  const std::string_view head = data.substr(start, 8);
  for (std::string_view kw : {"OFF", "COFF", "NOFF", "CNOFF", "STOFF", "4OFF", "nOFF"}) {
    if (head.starts_with(kw) && (head.size() == kw.size() || std::isspace(static_cast<unsigned char>(head[kw.size()]))))
      return true;
  }
  return false;
}

namespace {

struct OffHeader {
  long long vertex_count = 0, face_count = 0;
  bool has_normals = false;
};

/// The keyword line and the counts (on the keyword's line or the next one), checked against the
/// file's size.
OffHeader read_off_header(const fs::path& path, std::string_view data, LineReader& reader) {
  std::string_view line;
  if (!reader.next(line)) fail(path, "the file has no OFF header");
  std::vector<std::string_view> tokens = split(line);
  const std::string keyword(tokens[0]);
  if (!keyword.ends_with("OFF") || keyword.size() > 8) fail(path, "not an OFF file: it does not start with 'OFF'");
  if (keyword != "OFF" && keyword != "COFF" && keyword != "NOFF" && keyword != "CNOFF")
    fail(path, "unsupported OFF variant " + quote(keyword) + " (supported: OFF, COFF, NOFF, CNOFF)");
  if (tokens.size() > 1 && tokens[1] == "BINARY") fail(path, "binary OFF is not supported, only text OFF");
  OffHeader header;
  header.has_normals = keyword.find('N') != std::string::npos;

  // Counts may follow the keyword on its line or stand on the next one.
  tokens.erase(tokens.begin());
  if (tokens.empty()) {
    if (!reader.next(line)) fail(path, "truncated: the header has no vertex and face counts");
    tokens = split(line);
  }
  if (tokens.size() < 2) fail(path, "line " + std::to_string(reader.line_number()) + ": expected vertex and face counts");
  long long counts[2];
  for (int k = 0; k < 2; ++k)
    if (!parse_number(tokens[k], counts[k]))
      fail(path, "line " + std::to_string(reader.line_number()) + ": " + quote(tokens[k]) + " is not a count");
  const long long vertex_count = counts[0], face_count = counts[1];
  if (vertex_count < 0 || face_count < 0)
    fail(path, "header has negative counts (" + std::to_string(vertex_count) + " vertices, " + std::to_string(face_count) + " faces)");
  // Check the counts against the size before allocating: the shortest vertex line is "0 0 0\n"
  // (6 bytes) and the shortest face line "3 0 0 0\n" (8 bytes), so a hostile header cannot make us
  // reserve more than a small multiple of the file size.
  // Counts above 2^32 fail first, so the products below cannot overflow.
  const long long max_count = std::numeric_limits<std::uint32_t>::max();
  if (vertex_count > max_count || face_count > max_count || 6 * vertex_count + 8 * face_count > static_cast<long long>(data.size()))
    fail(path, "header says " + std::to_string(vertex_count) + " vertices and " + std::to_string(face_count) +
             " faces but the file has only " + std::to_string(data.size()) + " bytes");
  header.vertex_count = vertex_count, header.face_count = face_count;
  return header;
}

/// One vertex per line: x y z, then nx ny nz for NOFF (a colour after them is ignored).
void read_off_vertices(const fs::path& path, LineReader& reader, const OffHeader& header, Mesh& mesh) {
  mesh.positions.reserve(static_cast<std::size_t>(header.vertex_count) + kVertexPadding);  // see kVertexPadding
  if (header.has_normals) mesh.normals.reserve(static_cast<std::size_t>(header.vertex_count));
  const std::size_t coords_per_vertex = header.has_normals ? 6 : 3;
  std::string_view line;
  for (long long v = 0; v < header.vertex_count; ++v) {
    if (!reader.next(line))
      fail(path, "truncated: expected " + std::to_string(header.vertex_count) + " vertices, found " + std::to_string(v));
    const std::vector<std::string_view> tokens = split(line);
    if (tokens.size() < coords_per_vertex)
      fail(path, "line " + std::to_string(reader.line_number()) + ": vertex " + std::to_string(v) + " has " + std::to_string(tokens.size()) +
               " numbers, expected " + std::to_string(coords_per_vertex));
    float c[6];
    for (std::size_t k = 0; k < coords_per_vertex; ++k) {
      if (!parse_real(tokens[k], c[k]))
        fail(path, "line " + std::to_string(reader.line_number()) + ": vertex " + std::to_string(v) + ": " + quote(tokens[k]) + " is not a number");
      if (!std::isfinite(c[k]))
        fail(path, "vertex " + std::to_string(v) + " has a non-finite " + (k < 3 ? "coordinate" : "normal") + " (" + quote(tokens[k]) + ")");
    }
    mesh.positions.push_back({c[0], c[1], c[2]});
    if (header.has_normals) mesh.normals.push_back({c[3], c[4], c[5]});
  }
}

/// One face per line, "n i0 ... in-1" (a colour after them is ignored), fanned into triangles;
/// nothing may follow the last face.
void read_off_faces(const fs::path& path, LineReader& reader, const OffHeader& header, Mesh& mesh) {
  mesh.indices.reserve(static_cast<std::size_t>(header.face_count) * 3);
  std::vector<std::uint32_t> face;
  std::string_view line;
  for (long long f = 0; f < header.face_count; ++f) {
    if (!reader.next(line)) fail(path, "truncated: expected " + std::to_string(header.face_count) + " faces, found " + std::to_string(f));
    const std::vector<std::string_view> tokens = split(line);
    const std::string at = "line " + std::to_string(reader.line_number()) + ": face " + std::to_string(f);
    long long n = 0;
    if (!parse_number(tokens[0], n)) fail(path, at + ": " + quote(tokens[0]) + " is not a vertex count");
    if (n < 3) fail(path, at + " has " + std::to_string(n) + " vertices, at least 3 are needed");
    if (static_cast<long long>(tokens.size()) - 1 < n)
      fail(path, at + " says " + std::to_string(n) + " vertices but lists " + std::to_string(tokens.size() - 1));
    face.clear();
    for (long long k = 1; k <= n; ++k) {
      long long index = 0;
      if (!parse_number(tokens[static_cast<std::size_t>(k)], index))
        fail(path, at + ": " + quote(tokens[static_cast<std::size_t>(k)]) + " is not a vertex index");
      if (index < 0 || index >= header.vertex_count)
        fail(path, "face " + std::to_string(f) + " uses vertex " + std::to_string(index) + ", the file has " + std::to_string(header.vertex_count));
      face.push_back(static_cast<std::uint32_t>(index));
    }
    // Fan triangulation keeps the face's winding; it is exact for the convex faces OFF writers emit.
    for (std::size_t k = 1; k + 1 < face.size(); ++k) {
      mesh.indices.push_back(face[0]);
      mesh.indices.push_back(face[k]);
      mesh.indices.push_back(face[k + 1]);
    }
  }
  // More after the last face means the header's face count is short: reading only what it says
  // would drop faces without a word.
  if (reader.next(line))
    fail(path, "the header says " + std::to_string(header.face_count) + " faces, but line " + std::to_string(reader.line_number()) +
                   " after the last of them holds more (" + quote(split(line)[0]) + ")");
}

}  // namespace

Scene read_off(const fs::path& path, std::string_view data) {
  LineReader reader(data);
  const OffHeader header = read_off_header(path, data, reader);
  Mesh mesh;
  mesh.name = path.stem().string();
  read_off_vertices(path, reader, header, mesh);
  read_off_faces(path, reader, header, mesh);
  return io_detail::one_mesh_scene(path, std::move(mesh));
}

}  // namespace ao
