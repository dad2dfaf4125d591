// Mesh loading. OFF and PLY have readers of our own; OBJ, STL and glTF/GLB go through assimp, OBJ
// and glTF after a check of our own (obj_check.h, gltf_check.h), because assimp 5.2's readers fail
// the SPEC's bad-input rules. Measured with libassimp 5.2.5:
//  - OFF: a face index past the vertex list loads without complaint, a header claiming 4e8 vertices
//    allocates 7.8 GB and takes 24 s before failing, a file cut in the face list fails with
//    "aiMesh::mFaces[2258].mIndices is nullptr", and JoinIdenticalVertices makes cow.off's 2904
//    vertices 2903, so counts stop matching the header. OFF is a trivial format, so we parse it.
//  - PLY: see ply_reader.cpp (hangs, aborts, 16 GB allocations, invented faces, 400 bytes per
//    triangle).
//  - OBJ: `vt nan` is taken as a UV; one out-of-range UV index drops every UV of the file; and it
//    takes 0.28 CPU s for an 8 MB mesh. One-mesh files are read by obj_reader.cpp (4x faster, the
//    same result); the others after check_obj.
//  - ASCII STL: a file cut inside a facet loads the facets before the cut (stl_check.cpp).
//  - glTF/GLB: stack overflows on deep JSON or node chains, GLB chunk lengths trusted before the
//    file size, out-of-range indices and bad accessors read silently.
// Every other check (non-finite data, index ranges, empty faces, degenerate triangles) is shared: raw
// assimp data is checked before post-processing can merge, hide or trip over it, then
// validate_and_prepare runs on all. Found by tests and by fuzzing (fuzz/).
#include "ao/io/mesh_io.h"

#include <assimp/Importer.hpp>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <limits>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <vector>

#include "ao/core/error.h"
#include "ao/core/memory.h"
#include "ao/io/gltf_check.h"
#include "ao/io/number_text.h"
#include "ao/io/obj_check.h"
#include "ao/io/obj_reader.h"
#include "ao/io/ply_reader.h"
#include "ao/io/stl_check.h"

namespace ao {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const fs::path& path, const std::string& problem) { throw InputError(path.string() + ": " + problem); }

/// Messages must be one line; assimp's sometimes are not.
std::string one_line(std::string_view s) {
  std::string out;
  // assimp quotes file content in some messages: keep them printable and short.
  for (char c : s.substr(0, 200)) out += std::isspace(static_cast<unsigned char>(c)) ? ' ' : std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  while (!out.empty() && (out.back() == ' ' || out.back() == '.')) out.pop_back();
  return s.size() > 200 ? out + "..." : out;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

/// A file's whole content, mapped read-only: big meshes are hundreds of MB, and a mapping costs
/// neither a copy nor memory of our own (the pages are the page cache's).
class MappedFile {
 public:
  /// Checks that the path is a readable, non-empty regular file and maps it.
  explicit MappedFile(const fs::path& path) {
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (!fs::exists(st)) fail(path, "no such file");
    if (fs::is_directory(st)) fail(path, "is a directory, not a mesh file");
    if (!fs::is_regular_file(st)) fail(path, "is not a regular file");
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) fail(path, "cannot be opened for reading");
    struct stat info {};
    if (::fstat(fd, &info) != 0) {
      ::close(fd);
      fail(path, "cannot read its size");
    }
    size_ = static_cast<std::size_t>(info.st_size);
    if (size_ == 0) {
      ::close(fd);
      fail(path, "the file is empty");
    }
    void* addr = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
    ::close(fd);  // the mapping keeps the file
    if (addr == MAP_FAILED) throw SystemError(path.string() + ": cannot map the file into memory (" + std::to_string(size_) + " bytes)");
    data_ = static_cast<const char*>(addr);
  }
  ~MappedFile() { ::munmap(const_cast<char*>(data_), size_); }
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  std::string_view view() const { return {data_, size_}; }

 private:
  const char* data_ = nullptr;
  std::size_t size_ = 0;
};

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

/// Text from the file for a message: printable and short even if the file is garbage.
std::string printable(std::string_view token) {
  std::string out;
  for (char c : token.substr(0, 24)) out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  return token.size() > 24 ? out + "..." : out;
}
std::string quote(std::string_view token) {
  std::string out(1, '\'');  // appended piecewise: "'" + string trips GCC 12's false -Wrestrict
  out += printable(token);
  out += '\'';
  return out;
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

// ---------------------------------------------------------------------------------------------
// OFF (Geomview): [C][N]OFF, counts "vertices faces [edges]", one vertex per line (x y z, then
// nx ny nz for N, then a colour we ignore), one face per line ("n i0 ... in-1", then an ignored
// colour). '#' starts a comment.

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

Scene read_off(const fs::path& path, std::string_view data) {
  LineReader reader(data);
  const OffHeader header = read_off_header(path, data, reader);
  Mesh mesh;
  mesh.name = path.stem().string();
  read_off_vertices(path, reader, header, mesh);
  read_off_faces(path, reader, header, mesh);
  Scene scene;
  scene.name = path.filename().string();
  scene.meshes.push_back(std::move(mesh));
  validate_and_prepare(scene);
  return scene;
}

// ---------------------------------------------------------------------------------------------
// assimp

Vec3 material_albedo(const aiMaterial& material, bool format_has_materials) {
  const Vec3 fallback = Mesh{}.albedo;
  if (!format_has_materials) return fallback;
  aiString name;
  // assimp invents "DefaultMaterial" (grey 0.6, or white) for files that name no material; that is
  // not the author's colour, so the Mesh default applies.
  if (material.Get(AI_MATKEY_NAME, name) == aiReturn_SUCCESS && std::string_view(name.C_Str()) == AI_DEFAULT_MATERIAL_NAME) return fallback;
  aiColor4D c;
  // glTF's baseColorFactor arrives as BASE_COLOR (and usually also DIFFUSE); prefer it where present.
  if (material.Get(AI_MATKEY_BASE_COLOR, c) == aiReturn_SUCCESS || material.Get(AI_MATKEY_COLOR_DIFFUSE, c) == aiReturn_SUCCESS)
    return {c.r, c.g, c.b};
  return fallback;
}

std::string uv_set_error(unsigned sets, int asked) {
  return "has " + std::to_string(sets) + " UV set" + (sets == 1 ? "" : "s") + ", --uv-set " + std::to_string(asked) + " asked for";
}

/// Running out of memory inside assimp: the sizes were checked against the file before (PLY, OFF),
/// so this is the machine's limit, a SystemError (exit 3), not bad input.
[[noreturn]] void out_of_memory(const fs::path& path) {
  throw SystemError(path.string() + ": out of memory while reading the mesh");
}

/// assimp catches std::bad_alloc itself and keeps only its what() as the error string. The match is
/// exact: assimp's messages quote the file's own tokens, and a file may well contain "bad_alloc".
bool assimp_ran_out_of_memory(std::string_view error) { return error == std::bad_alloc().what(); }

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

std::string mesh_label(const aiMesh& m, unsigned index) {
  return m.mName.length > 0 ? "mesh '" + std::string(m.mName.C_Str()) + "'" : "mesh " + std::to_string(index);
}

/// Faces without indices, and non-finite values (of the UV set that is loaded), checked before JoinIdenticalVertices can merge or hide them (it joins NaN
/// vertices with their neighbours, which turns the error into a "degenerate triangle").
void check_raw_meshes(const fs::path& path, const aiScene& scene, unsigned uv_set) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh& mesh = *scene.mMeshes[m];
    const std::string where = scene.mNumMeshes > 1 ? " of " + mesh_label(mesh, m) : "";
    // ValidateDataStructure lets faces with no indices through, and assimp's Triangulate step then
    // aborts the process on an assertion (seen on a corrupted binary PLY), so they stop here.
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices == 0 || face.mIndices == nullptr) fail(path, "face " + std::to_string(f) + where + " has no vertices");
      for (unsigned k = 0; k < face.mNumIndices; ++k)
        if (face.mIndices[k] >= mesh.mNumVertices)
          fail(path, "face " + std::to_string(f) + where + " uses vertex " + std::to_string(face.mIndices[k]) + ", the mesh has " +
                         std::to_string(mesh.mNumVertices));
    }
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D p = mesh.mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        fail(path, "vertex " + std::to_string(v) + where + " has a non-finite coordinate");
      if (mesh.HasNormals()) {
        const aiVector3D n = mesh.mNormals[v];
        if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z))
          fail(path, "normal " + std::to_string(v) + where + " is not finite");
      }
      if (uv_set < AI_MAX_NUMBER_OF_TEXTURECOORDS && mesh.HasTextureCoords(uv_set)) {
        const aiVector3D t = mesh.mTextureCoords[uv_set][v];
        if (!std::isfinite(t.x) || !std::isfinite(t.y))
          fail(path, "UV " + std::to_string(v) + (uv_set ? " of UV set " + std::to_string(uv_set) : std::string()) + where + " is not finite");
      }
    }
  }
}

Affine3 to_affine(const aiMatrix4x4& m) {
  // aiMatrix4x4 is row-major with the translation in the fourth column (a4, b4, c4).
  return {{m.a1, m.b1, m.c1}, {m.a2, m.b2, m.c2}, {m.a3, m.b3, m.c3}, {m.a4, m.b4, m.c4}};
}

/// Every use of a mesh by the node tree: the mesh and its node's world transform (the product of
/// the transforms from the root down), in depth-first node order. Iterative: the depth is bounded
/// by check_gltf, but an explicit stack does not depend on that.
struct MeshUse {
  unsigned mesh;
  aiMatrix4x4 world;
  const aiNode* node;
};
std::vector<MeshUse> mesh_uses(const aiScene& scene) {
  std::vector<MeshUse> uses;
  if (scene.mRootNode == nullptr) return uses;
  std::vector<std::pair<const aiNode*, aiMatrix4x4>> stack{{scene.mRootNode, scene.mRootNode->mTransformation}};
  while (!stack.empty()) {
    const auto [node, world] = stack.back();
    stack.pop_back();
    for (unsigned i = 0; i < node->mNumMeshes; ++i)
      if (node->mMeshes[i] < scene.mNumMeshes) uses.push_back({node->mMeshes[i], world, node});
    // Children pushed in reverse so that they are visited in the file's order.
    for (unsigned c = node->mNumChildren; c-- > 0;)
      if (node->mChildren[c] != nullptr) stack.emplace_back(node->mChildren[c], world * node->mChildren[c]->mTransformation);
  }
  return uses;
}

/// Every node that places triangles has a finite transform that does not flatten them
/// (determinant 0 makes every triangle degenerate, a mesh used once as much as an instance): the
/// rule validate_and_prepare applies to instances, here for every use, flattened or not.
void check_node_transforms(const fs::path& path, const aiScene& scene) {
  for (const MeshUse& u : mesh_uses(scene)) {
    if ((scene.mMeshes[u.mesh]->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0 && scene.mMeshes[u.mesh]->mPrimitiveTypes != 0) continue;
    std::string name;
    for (char c : std::string_view(u.node->mName.C_Str()).substr(0, 64)) name += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
    const std::string label = name.empty() ? "a node" : "node '" + name + "'";
    const Affine3 t = to_affine(u.world);
    if (!t.is_finite()) fail(path, label + " has a non-finite transform");
    const double det = t.determinant();
    if (!(std::abs(det) > 0) || !std::isfinite(1.0 / det)) fail(path, label + " has a transform with determinant 0 (it flattens the mesh)");
  }
}

/// True when the node tree uses some mesh more than once.
bool uses_a_mesh_twice(const aiScene& scene) {
  std::vector<unsigned> refs(scene.mNumMeshes, 0);
  for (const MeshUse& u : mesh_uses(scene))
    if (++refs[u.mesh] > 1) return true;
  return false;
}

/// One assimp mesh as a Mesh, in the coordinates the file gives it.
Mesh convert_mesh(const aiScene& ai, const aiMesh& in, unsigned uv_set, bool format_has_materials) {
  Mesh mesh;
  mesh.name = in.mName.C_Str();
  mesh.positions.reserve(in.mNumVertices + kVertexPadding);  // see kVertexPadding
  for (unsigned v = 0; v < in.mNumVertices; ++v) mesh.positions.push_back({in.mVertices[v].x, in.mVertices[v].y, in.mVertices[v].z});
  if (in.HasNormals()) {
    mesh.normals.reserve(in.mNumVertices);
    for (unsigned v = 0; v < in.mNumVertices; ++v) mesh.normals.push_back({in.mNormals[v].x, in.mNormals[v].y, in.mNormals[v].z});
  }
  if (uv_set < AI_MAX_NUMBER_OF_TEXTURECOORDS && in.HasTextureCoords(uv_set)) {
    mesh.uvs.reserve(in.mNumVertices);
    for (unsigned v = 0; v < in.mNumVertices; ++v) mesh.uvs.push_back({in.mTextureCoords[uv_set][v].x, in.mTextureCoords[uv_set][v].y});
  }
  mesh.indices.reserve(static_cast<std::size_t>(in.mNumFaces) * 3);
  for (unsigned f = 0; f < in.mNumFaces; ++f) {
    const aiFace& face = in.mFaces[f];
    if (face.mNumIndices != 3) continue;  // SortByPType leaves triangles only; be safe anyway
    mesh.indices.insert(mesh.indices.end(), face.mIndices, face.mIndices + 3);
  }
  if (in.mMaterialIndex < ai.mNumMaterials) mesh.albedo = material_albedo(*ai.mMaterials[in.mMaterialIndex], format_has_materials);
  return mesh;
}

/// The meshes of a node tree that uses some mesh several times: a mesh used once is moved to
/// world space (normals through the cofactor matrix, so they stay on the side the transformed
/// winding faces); a mesh used more often is kept once in object space, and each use becomes an
/// Instance named after its node. Meshes no node uses are left out (as pre-transforming does).
void convert_instanced(const aiScene& ai, unsigned uv_set, bool format_has_materials, Scene& scene) {
  const std::vector<MeshUse> uses = mesh_uses(ai);
  std::vector<unsigned> refs(ai.mNumMeshes, 0);
  for (const MeshUse& u : uses) ++refs[u.mesh];
  std::vector<std::uint32_t> index(ai.mNumMeshes, SceneObject::kNoInstance);
  for (const MeshUse& u : uses) {
    const aiMesh& in = *ai.mMeshes[u.mesh];
    if ((in.mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0) continue;
    const Affine3 t = to_affine(u.world);
    if (refs[u.mesh] == 1) {
      Mesh mesh = convert_mesh(ai, in, uv_set, format_has_materials);
      const Affine3 n = cofactor(t);
      for (Vec3& p : mesh.positions) p = t.point(p);
      for (Vec3& v : mesh.normals) v = normalize(n.vector(v));
      scene.meshes.push_back(std::move(mesh));
      continue;
    }
    if (index[u.mesh] == SceneObject::kNoInstance) {
      index[u.mesh] = static_cast<std::uint32_t>(scene.meshes.size());
      scene.meshes.push_back(convert_mesh(ai, in, uv_set, format_has_materials));
    }
    scene.instances.push_back({index[u.mesh], t, u.node->mName.C_Str()});
  }
}

/// One assimp step (reading or post-processing) with its failures in ao's words: running out of
/// memory is the machine's limit, anything else the file's fault. `ext`: the file's extension when
/// the step reads it, empty for a post-processing step.
template <class Step>
const aiScene* assimp_step(const fs::path& path, Assimp::Importer& importer, std::string_view ext, Step&& step) {
  const aiScene* result = nullptr;
  try {
    result = step();
  } catch (const std::bad_alloc&) {
    out_of_memory(path);
  } catch (const std::exception& e) {
    fail(path, explain_assimp_error(e.what()));
  }
  if (result != nullptr) return result;
  const std::string error = importer.GetErrorString();
  if (assimp_ran_out_of_memory(error)) out_of_memory(path);
  // "No suitable reader" for a file named like a format assimp reads means damaged content.
  if (error.find("No suitable reader found") != std::string::npos && !ext.empty() && importer.IsExtensionSupported(std::string(ext)))
    fail(path, "malformed or truncated " + printable(ext.substr(1)) + " file: its content is not recognised");
  fail(path, explain_assimp_error(error));
}

/// The UV set asked for: a set above 0 that no mesh has is a mistake worth stopping on (set 0
/// missing is the "no UVs" case the callers report in their own terms).
void check_uv_set(const fs::path& path, const aiScene& ai, int asked) {
  const auto uv_set = static_cast<unsigned>(asked);
  if (uv_set == 0) return;
  unsigned sets = 0;
  bool found = false;
  for (unsigned m = 0; m < ai.mNumMeshes; ++m) {
    sets = std::max(sets, ai.mMeshes[m]->GetNumUVChannels());
    found = found || (uv_set < AI_MAX_NUMBER_OF_TEXTURECOORDS && ai.mMeshes[m]->HasTextureCoords(uv_set));
  }
  if (!found) fail(path, uv_set_error(sets, asked));
}

Scene read_with_assimp(const fs::path& path, std::string_view data, const LoadOptions& options, bool is_gltf) {
  const std::string ext = lower(path.extension().string());
  const bool is_stl = ext == ".stl" || data.starts_with("solid");
  // STL, PLY and OFF carry no materials; assimp's stand-in colour for them is white.
  const bool format_has_materials = !(is_stl || looks_like_ply(data));

  Assimp::Importer importer;
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  // STL stores one normal per facet, which would keep every triangle's corners apart; dropping them
  // lets JoinIdenticalVertices weld the soup, and validate_and_prepare makes smooth normals.
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS);

  // Read with validation only, check the raw data, then post-process.
  const aiScene* raw = assimp_step(path, importer, ext, [&] { return importer.ReadFile(path.string(), aiProcess_ValidateDataStructure); });
  check_raw_meshes(path, *raw, static_cast<unsigned>(options.uv_set));
  if (is_gltf) check_node_transforms(path, *raw);
  // A glTF whose node tree uses a mesh several times keeps the mesh once, with instances
  // (convert_instanced); everything else is pre-transformed into world space by assimp, which
  // also joins the meshes that share a material and vertex format into one.
  const bool instanced = is_gltf && !options.flatten_instances && uses_a_mesh_twice(*raw);

  // No GenNormals / GenSmoothNormals (validate_and_prepare makes normals), and no FindInvalidData or
  // FixInfacingNormals, which would change the data without telling anyone.
  unsigned steps = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType;
  if (!instanced) steps |= aiProcess_PreTransformVertices;
  if (is_stl) steps |= aiProcess_RemoveComponent;
  const aiScene* ai = assimp_step(path, importer, {}, [&] { return importer.ApplyPostProcessing(steps); });
  check_uv_set(path, *ai, options.uv_set);

  const unsigned uv_set = static_cast<unsigned>(options.uv_set);
  Scene scene;
  scene.name = path.filename().string();
  if (instanced) {
    convert_instanced(*ai, uv_set, format_has_materials, scene);
  } else {
    for (unsigned m = 0; m < ai->mNumMeshes; ++m) {
      const aiMesh& in = *ai->mMeshes[m];
      if ((in.mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0) continue;
      scene.meshes.push_back(convert_mesh(*ai, in, uv_set, format_has_materials));
    }
  }
  if (scene.meshes.empty()) fail(path, "the file has no triangles");
  validate_and_prepare(scene);
  return scene;
}

/// Refuses, before assimp reads anything, a glTF whose meshes (shared accessors, meshes used by
/// many nodes) expand beyond the memory available: assimp's copy of every mesh, its world-space
/// copy per use when flattening (pre-transform; each copy joined once more), and the Scene's
/// arrays (positions, normals and UVs 32 bytes per vertex, 12 per triangle). Instancing keeps
/// each mesh once, and an instance costs next to nothing. Measured against this bound: a 100k-
/// instance file reached 8.1 GB when flattened (issue 27), what the world term gives.
void check_gltf_memory(const fs::path& path, const GltfSize& size, const LoadOptions& options) {
  const GltfSize::Counts& placed = options.flatten_instances ? size.world : size.stored;
  const std::uint64_t scene_bytes = placed.vertices * 32 + placed.triangles * 12;
  const std::uint64_t bytes = 2 * size.stored.bytes + 2 * placed.bytes + scene_bytes;
  check_memory(bytes, path.string() + ": loading " + std::to_string(placed.triangles) + " triangles (" + std::to_string(size.uses) +
                          " mesh uses" + (options.flatten_instances ? ", each a copy" : "") + ")");
}

}  // namespace

Scene load_scene_file(const fs::path& path, const LoadOptions& options) {
  if (options.uv_set < 0) fail(path, "--uv-set " + std::to_string(options.uv_set) + " asked for, UV sets count from 0");
  // The whole file is mapped up front: our readers and checks need it, and the size checks of
  // counts need its length.
  const MappedFile file(path);
  const std::string_view data = file.view();
  const std::string ext = lower(path.extension().string());
  if (ext == ".off" || looks_like_off(data)) {
    if (options.uv_set > 0) fail(path, uv_set_error(0, options.uv_set));  // OFF has no UVs
    return read_off(path, data);
  }
  if (ext == ".ply" || looks_like_ply(data)) {
    if (!looks_like_ply(data)) fail(path, "not a PLY file: it does not start with 'ply'");
    try {
      Scene scene = read_ply(path, data);
      if (options.uv_set > 0) fail(path, uv_set_error(scene.meshes[0].uvs.empty() ? 0 : 1, options.uv_set));
      validate_and_prepare(scene);
      return scene;
    } catch (const std::bad_alloc&) {
      // The reader allocates no more than the checked counts need, so this is a real shortage.
      throw SystemError(path.string() + ": out of memory loading the mesh (" + std::to_string(data.size()) + " bytes of file)");
    }
  }
  const bool is_gltf = looks_like_gltf(path, data);
  if (is_gltf) check_gltf_memory(path, check_gltf(path, data, options.asset_root), options);
  else if (ext == ".obj") {
    if (std::optional<Scene> scene = read_simple_obj(path, data, options)) return std::move(*scene);
    check_obj(path, data, options.asset_root);
  }
  else if (is_ascii_stl(data)) check_ascii_stl(path, data);
  else if (ext == ".stl") check_binary_stl(path, data);
  return read_with_assimp(path, data, options, is_gltf);
}

}  // namespace ao
