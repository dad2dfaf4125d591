// SPDX-License-Identifier: Apache-2.0
// assimp's messages in ao's words (found by scripts/mutate, tested case by case in
// tests/io/loader_messages_test.cpp).
#include <string>
#include <string_view>

#include "ao/io/assimp_internal.h"
#include "ao/io/io_error_internal.h"

namespace ao::io_detail {

namespace {

/// assimp's messages for the malformed files it meets most (found by scripts/mutate), in ao's
/// words: a needle of assimp's message, and what ao says instead. Tested case by case in
/// tests/io/loader_messages_test.cpp.
struct AssimpWords {
  std::string_view needle, words;
};
constexpr AssimpWords kAssimpWords[] = {
    {"No suitable reader found", "unknown or unreadable mesh format (supported: OBJ, PLY, OFF, STL, glTF/GLB and other formats assimp reads)"},
    {"No meshes remaining", "the file has no triangles, only points or lines"},
    {"mNumMeshes is 0", "the file contains no meshes"},
    {"Failed to determine STL storage representation", "not an STL file: neither ASCII STL ('solid ...') nor binary STL (84 bytes, then 50 per triangle)"},
    {"File is too small", "truncated: the file is too small to hold its format's header"},
    {"contains no faces", "a mesh of the file has no faces"},
    {" is a LINE but ", "a face has only 2 corners (a line)"},
    {" is a POINT but ", "a face has only 1 corner (a point)"},
    {"OBJ: Invalid face index", "an index of a face, line or point cannot be read (a comment after it?)"},
    {"OBJ: bad vertex index", "a line (l) or face has too few vertices"},
    {"vertex normal index out of range", "normals are missing for some vertices"},
    {"texture coordinate index out of range", "a face refers to a UV that does not exist"},
    {"vertex color index out of range", "a vertex colour is missing"},
    {"OBJ: Invalid number of components", "a v, vt or vn line has the wrong number of values"},
    {"Invalid accessor without data", "a mesh uses an accessor that has no data"},
    {"GLTF: No scene", "the file has no scene to load"},
    {"A count value is required", "an accessor has no count"},
    {"data is null when extracting data", "an accessor has no data"},
};

/// The `nth` double-quoted word of `s` (0-based), or empty.
std::string quoted(const std::string& s, int nth) {
  std::size_t pos = 0;
  for (int k = 0; k <= nth; ++k) {
    const std::size_t open = s.find('"', pos);
    if (open == std::string::npos) return {};
    const std::size_t close = s.find('"', open + 1);
    if (close == std::string::npos) return {};
    if (k == nth) return s.substr(open + 1, close - open - 1);
    pos = close + 1;
  }
  return {};
}

/// What follows "when reading " in an assimp glTF message ("materials[0]"), without assimp's
/// repetition in parentheses; empty when absent.
std::string reading_what(const std::string& e) {
  const std::size_t at = e.find("when reading ");
  if (at == std::string::npos) return {};
  std::string what = e.substr(at + 13);
  what = what.substr(0, std::min(what.find(' '), what.size()));
  return what == "the" ? std::string() : what;
}

}  // namespace

/// Explains assimp's error in the user's terms where we recognise it (kAssimpWords, and two
/// message shapes of its glTF reader); keeps assimp's words otherwise.
std::string explain_assimp_error(std::string_view error) {
  const std::string e = one_line(error);
  for (const AssimpWords& w : kAssimpWords)
    if (e.find(w.needle) != std::string::npos) {
      const std::string where = reading_what(e);
      return std::string(w.words) + (where.empty() ? "" : " (" + where + ")");
    }
  // Member "matrix" was not of type "array" when reading nodes[1] (nodes[1])
  if (e.find("was not of type") != std::string::npos && !quoted(e, 0).empty()) {
    const std::string where = reading_what(e), type = quoted(e, 1);
    const std::string article = !type.empty() && std::string_view("aeiou").find(type[0]) != std::string_view::npos ? "an " : "a ";
    return (where.empty() ? "" : where + ".") + quoted(e, 0) + " is not " + article + type;
  }
  // GLTF: Object at index 0 in array "materials" is not a JSON object
  if (e.find("Object at index") != std::string::npos && !quoted(e, 0).empty()) {
    const std::size_t at = e.find("at index ") + 9;
    return quoted(e, 0) + "[" + e.substr(at, e.find(' ', at) - at) + "] is not an object";
  }
  // GLTF: Missing section "materials"
  if (e.find("Missing section") != std::string::npos && !quoted(e, 0).empty())
    return "the file refers to its " + quoted(e, 0) + " but has none";
  return "malformed or truncated file (" + e + ")";
}

/// assimp catches std::bad_alloc itself and keeps only its what() as the error string. The match is
/// exact: assimp's messages quote the file's own tokens, and a file may well contain "bad_alloc".
bool assimp_ran_out_of_memory(std::string_view error) { return error == std::bad_alloc().what(); }

std::string uv_set_error(unsigned sets, int asked) {
  return "has " + std::to_string(sets) + " UV set" + (sets == 1 ? "" : "s") + ", --uv-set " + std::to_string(asked) + " asked for";
}

}  // namespace ao::io_detail
