// SPDX-License-Identifier: Apache-2.0
// Fast OBJ reader for one-mesh files (obj_reader.h). One pass over the mapped file collects the
// numbers and the face corners; anything outside the supported shape ends the attempt (nullopt),
// and load_scene_file reads the file as it always did. What assimp 5.2 and ao's post-processing
// made of a one-mesh OBJ, and how this reader gets the same:
//  - The OBJ importer gives every face corner a vertex of its own; JoinIdenticalVertices welds the
//    corners whose position, UV and normal are equal, keeping the first in corner order. Here each
//    attribute value is numbered once (equal values, also from different lines, share a number;
//    -0 and +0 are equal), and each distinct (position, UV, normal) triple becomes a vertex when a
//    corner first uses it: the same vertices in the same order. (assimp welds within 1e-5; real
//    meshes have no distinct vertices that close, and a mesh scaled far down keeps its vertices
//    apart here, as a tiny mesh should.)
//  - Triangulate splits a quad into (s, s+1, s+2) and (s, s+2, s+3), s being its concave corner if
//    it has one (the angles at a corner to the diagonal and the two edges sum above pi), else 0;
//    the test below is assimp's, in float.
//  - The mesh is named after the object ("o name") or group ("g name") line, "defaultobject"
//    without one; the albedo is the material's Kd (material_albedo in assimp_reader.cpp).
// Numbers are read by from_chars, correctly rounded; assimp's fast_atof can differ in the last bit.
#include "ao/io/obj_reader.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <unordered_map>
#include <vector>

#include "ao/core/error.h"
#include "ao/io/asset_path.h"
#include "ao/io/number_text.h"
#include "ao/io/one_mesh_scene_internal.h"

namespace ao {
namespace {

namespace fs = std::filesystem;

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

/// Whitespace-separated tokens of one line (comment already removed).
struct Tokens {
  std::string_view line;
  std::size_t pos = 0;
  std::string_view next() {
    while (pos < line.size() && is_blank(line[pos])) ++pos;
    const std::size_t start = pos;
    while (pos < line.size() && !is_blank(line[pos])) ++pos;
    return line.substr(start, pos - start);
  }
};

/// A finite float, or false.
bool read_float(std::string_view token, float& value) {
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc() || ptr != token.data() + token.size()) {
    // '+1', underflow to a denormal or 0: the reading every text format shares.
    if (!parse_real(token, value)) return false;
  }
  return std::isfinite(value);
}

bool read_index(std::string_view part, long long& value) {
  const auto [ptr, ec] = std::from_chars(part.data(), part.data() + part.size(), value);
  return ec == std::errc() && ptr == part.data() + part.size() && value != 0;
}

/// Bits of a value for equality, with -0 and +0 alike (float equality, as assimp compares).
template <std::size_t N>
std::array<std::uint32_t, N> key_of(const std::array<float, N>& v) {
  std::array<std::uint32_t, N> k{};
  for (std::size_t i = 0; i < N; ++i) {
    const float f = v[i] + 0.0f;  // -0 + 0 = +0
    std::memcpy(&k[i], &f, 4);
  }
  return k;
}

struct KeyHash {
  template <std::size_t N>
  std::size_t operator()(const std::array<std::uint32_t, N>& k) const {
    std::uint64_t h = 0x9E3779B97F4A7C15ull;
    for (std::uint32_t x : k) h = (h ^ x) * 0xFF51AFD7ED558CCDull, h ^= h >> 32;
    return static_cast<std::size_t>(h);
  }
};

/// The line of `data` that starts at `pos` (without its newline); `pos` moves to the next line.
std::string_view next_line(std::string_view data, std::size_t& pos) {
  const char* nl = static_cast<const char*>(std::memchr(data.data() + pos, '\n', data.size() - pos));
  const std::size_t end = nl ? static_cast<std::size_t>(nl - data.data()) : data.size();
  const std::string_view line = data.substr(pos, end - pos);
  pos = end + 1;
  return line;
}

/// For each value of `values`, the index of the first equal value.
template <std::size_t N>
std::vector<std::uint32_t> first_equal(const std::vector<std::array<float, N>>& values) {
  std::unordered_map<std::array<std::uint32_t, N>, std::uint32_t, KeyHash> seen;
  seen.reserve(values.size());
  std::vector<std::uint32_t> out(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) out[i] = seen.try_emplace(key_of(values[i]), static_cast<std::uint32_t>(i)).first->second;
  return out;
}

/// The Kd colour of material `name` in the library files `libraries` (in the asset's folder), or
/// false when it is not there exactly once with one plain "Kd r g b" line.
bool material_colour(const fs::path& model, const std::vector<std::string>& libraries, std::string_view name, Vec3& colour) {
  int found = 0;
  for (const std::string& lib : libraries) {
    std::ifstream in(model.parent_path() / lib, std::ios::binary);
    if (!in) return false;
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    bool inside = false;
    int kd_lines = 0;
    std::size_t pos = 0;
    while (pos < text.size()) {
      const std::size_t end = std::min(text.find('\n', pos), text.size());
      std::string_view line = std::string_view(text).substr(pos, end - pos);
      pos = end + 1;
      line = line.substr(0, std::min(line.find('#'), line.size()));
      Tokens t{line};
      const std::string_view key = t.next();
      if (key == "newmtl") {
        if (inside && kd_lines != 1) return false;
        const std::string_view n = t.next();
        inside = n == name && t.next().empty();
        if (inside && ++found > 1) return false;
        kd_lines = 0;
      } else if (inside && key == "Kd") {
        float c[3];
        for (float& v : c)
          if (!read_float(t.next(), v)) return false;
        if (!t.next().empty()) return false;
        colour = {c[0], c[1], c[2]};
        ++kd_lines;
      }
    }
    if (inside && kd_lines != 1) return false;
  }
  return found == 1;
}

/// Corner forms, by which indices a corner has.
enum Form { kV = 0, kVT = 1, kVN = 2, kVTN = 3, kUnset = -1 };

/// A corner's "v", "v/vt", "v//vn" or "v/vt/vn"; false for anything else.
bool read_corner(std::string_view c, long long idx[3], Form& form) {
  const std::size_t s1 = c.find('/');
  if (s1 == std::string_view::npos) {
    form = kV;
    return read_index(c, idx[0]);
  }
  if (!read_index(c.substr(0, s1), idx[0])) return false;
  const std::size_t s2 = c.find('/', s1 + 1);
  if (s2 == std::string_view::npos) {
    form = kVT;
    return read_index(c.substr(s1 + 1), idx[1]);
  }
  const std::string_view t = c.substr(s1 + 1, s2 - s1 - 1), n = c.substr(s2 + 1);
  if (!read_index(n, idx[2])) return false;
  if (t.empty()) {
    form = kVN;
    return true;
  }
  form = kVTN;
  return read_index(t, idx[1]);
}

/// assimp's concave-corner test for a quad (TriangulateProcess): the corner whose two angles to
/// the opposite diagonal sum above pi, or 0. Without fused multiply-adds, which the build's
/// -march=native would allow and Debian's assimp does not use: the same roundings as assimp's.
#if defined(__clang__)
int quad_start(const Vec3 p[4]) {
#pragma clang fp contract(off)
#elif defined(__GNUC__)
__attribute__((optimize("fp-contract=off"))) int quad_start(const Vec3 p[4]) {
#else
int quad_start(const Vec3 p[4]) {
#endif
  // As aiVector3D::Normalize, bit for bit: times the reciprocal of the length, a zero vector kept.
  const auto unit = [](Vec3 a) {
    const float len = std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z);
    if (len == 0.0f) return a;
    const float inv = 1.0f / len;
    return Vec3{a.x * inv, a.y * inv, a.z * inv};
  };
  for (int i = 0; i < 4; ++i) {
    const Vec3 v = p[i];
    const Vec3 left = unit(p[(i + 3) % 4] - v), diag = unit(p[(i + 2) % 4] - v), right = unit(p[(i + 1) % 4] - v);
    const float angle = std::acos(left.x * diag.x + left.y * diag.y + left.z * diag.z) + std::acos(right.x * diag.x + right.y * diag.y + right.z * diag.z);
    if (angle > 3.14159265358979323846f) return i;
  }
  return 0;
}

/// What one pass over the file collects, in the file's terms.
struct ObjData {
  std::vector<std::array<float, 3>> positions, normals;
  std::vector<std::array<float, 2>> uvs;
  // Face corners as read (attribute indices resolved to 0-based), 3 or 4 per face.
  std::vector<std::array<std::uint32_t, 3>> corners;
  std::vector<std::uint8_t> face_sizes;
  std::vector<std::array<long long, 3>> forward;  // positive indices, checked once the counts are known
  std::vector<std::string> libraries;
  std::string object_name = "defaultobject", material;
  int object_lines = 0, material_lines = 0;
  Form form = kUnset;

  /// An f line's corners, all of one form, 3 or 4; false outside the supported shape.
  bool read_face(Tokens& t) {
    std::uint8_t n = 0;
    for (std::string_view c = t.next(); !c.empty(); c = t.next()) {
      long long idx[3] = {0, 0, 0};
      Form f = kUnset;
      if (n == 4 || !read_corner(c, idx, f)) return false;
      if (form == kUnset) form = f;
      if (f != form) return false;
      const std::size_t counts[3] = {positions.size(), uvs.size(), normals.size()};
      std::array<std::uint32_t, 3> resolved{0, 0, 0};
      bool later = false;
      for (int k = 0; k < 3; ++k) {
        if (idx[k] == 0) continue;  // absent
        if (idx[k] < 0) {
          if (static_cast<unsigned long long>(-idx[k]) > counts[k]) return false;
          resolved[static_cast<std::size_t>(k)] = static_cast<std::uint32_t>(static_cast<long long>(counts[k]) + idx[k]);
        } else {
          if (idx[k] > 0xFFFFFFFFll) return false;
          resolved[static_cast<std::size_t>(k)] = static_cast<std::uint32_t>(idx[k] - 1);
          later = later || static_cast<unsigned long long>(idx[k]) > counts[k];
        }
      }
      if (later) forward.push_back({idx[0], idx[1], idx[2]});
      corners.push_back(resolved);
      ++n;
    }
    if (n < 3) return false;
    face_sizes.push_back(n);
    return true;
  }

  /// One line (comment removed); false outside the supported shape.
  bool read_line(const fs::path& path, const fs::path& folder, std::string_view line) {
    Tokens t{line};
    const std::string_view key = t.next();
    if (key.empty()) return true;
    if (key == "v" || key == "vn") {
      std::array<float, 3> v;
      for (float& x : v)
        if (!read_float(t.next(), x)) return false;
      if (!t.next().empty()) return false;  // w or a vertex colour
      (key == "v" ? positions : normals).push_back(v);
    } else if (key == "vt") {
      std::array<float, 2> v;
      for (float& x : v)
        if (!read_float(t.next(), x)) return false;
      const std::string_view w = t.next();
      float ignored = 0;
      if (!w.empty() && (!read_float(w, ignored) || !t.next().empty())) return false;
      uvs.push_back(v);
    } else if (key == "f") {
      return read_face(t);
    } else if (key == "o" || key == "g") {
      const std::string_view name = t.next();
      if (!face_sizes.empty() || ++object_lines > 1 || name.empty() || !t.next().empty()) return false;
      object_name = name;
    } else if (key == "usemtl") {
      const std::string_view name = t.next();
      if (!face_sizes.empty() || ++material_lines > 1 || name.empty() || !t.next().empty()) return false;
      material = name;
    } else if (key == "mtllib") {
      const std::string_view name = t.next();
      // assimp looks the material up when it meets usemtl; a name with spaces is its reading too.
      if (material_lines > 0 || name.empty() || !t.next().empty()) return false;
      resolve_asset_reference(path, folder, name, "material library");
      libraries.emplace_back(name);
    } else if (key != "s") {
      return false;
    }
    return true;
  }

  /// Room for the elements of `data`, counted by the first word of each line, so that the arrays
  /// fill without growing (each growth copies them into fresh pages). Quads take more corners than
  /// three per face: those arrays grow once.
  void reserve_for(std::string_view data) {
    std::size_t v = 0, vt = 0, vn = 0, f = 0;
    for (std::size_t pos = 0; pos < data.size();) {
      const std::string_view key = Tokens{next_line(data, pos)}.next();
      v += key == "v", vt += key == "vt", vn += key == "vn", f += key == "f";
    }
    positions.reserve(v), uvs.reserve(vt), normals.reserve(vn);
    corners.reserve(3 * f), face_sizes.reserve(f);
  }

  /// Whether every index that pointed forwards lands on an element of the whole file.
  bool forward_indices_in_range() const {
    for (const auto& idx : forward)
      if (static_cast<unsigned long long>(idx[0]) > positions.size() || static_cast<unsigned long long>(idx[1]) > uvs.size() ||
          static_cast<unsigned long long>(idx[2]) > normals.size())
        return false;
    return true;
  }
};

/// The mesh assimp would make of it: equal values share a number, then each distinct (position,
/// UV, normal) triple is a vertex in first-use order; quads split at their concave corner.
Mesh weld_and_triangulate(const ObjData& d) {
  const bool has_uv = d.form == kVT || d.form == kVTN, has_normal = d.form == kVN || d.form == kVTN;
  const std::vector<std::uint32_t> pos_id = first_equal(d.positions);
  const std::vector<std::uint32_t> uv_id = has_uv ? first_equal(d.uvs) : std::vector<std::uint32_t>{};
  const std::vector<std::uint32_t> normal_id = has_normal ? first_equal(d.normals) : std::vector<std::uint32_t>{};
  // The vertices made so far, chained per position number (a position has a few UV and normal
  // partners at most, one per chart or crease it lies on): no hashing, no allocation per vertex.
  constexpr std::uint32_t kNone = 0xFFFFFFFFu;
  std::vector<std::uint32_t> first_at(d.positions.size(), kNone), next_at;
  std::vector<std::array<std::uint32_t, 2>> partners;  // each vertex's UV and normal numbers
  next_at.reserve(d.positions.size()), partners.reserve(d.positions.size());
  Mesh mesh;
  mesh.name = d.object_name;
  mesh.positions.reserve(d.positions.size() + kVertexPadding);  // see kVertexPadding
  std::vector<std::uint32_t> corner_vertex(d.corners.size());
  for (std::size_t c = 0; c < d.corners.size(); ++c) {
    const auto& corner = d.corners[c];
    const std::uint32_t p = pos_id[corner[0]], uv = has_uv ? uv_id[corner[1]] : 0u, normal = has_normal ? normal_id[corner[2]] : 0u;
    std::uint32_t v = first_at[p];
    while (v != kNone && partners[v] != std::array<std::uint32_t, 2>{uv, normal}) v = next_at[v];
    if (v == kNone) {
      v = static_cast<std::uint32_t>(mesh.positions.size());
      next_at.push_back(first_at[p]);
      first_at[p] = v;
      partners.push_back({uv, normal});
      const auto& q = d.positions[p];
      mesh.positions.push_back({q[0], q[1], q[2]});
      if (has_uv) mesh.uvs.push_back({d.uvs[uv][0], d.uvs[uv][1]});
      if (has_normal) mesh.normals.push_back({d.normals[normal][0], d.normals[normal][1], d.normals[normal][2]});
    }
    corner_vertex[c] = v;
  }
  mesh.indices.reserve(d.corners.size() * 3 / 2 + 3);
  std::size_t c = 0;
  for (const std::uint8_t n : d.face_sizes) {
    const std::uint32_t* v = &corner_vertex[c];
    if (n == 3) {
      mesh.indices.insert(mesh.indices.end(), v, v + 3);
    } else {
      const Vec3 p[4] = {mesh.positions[v[0]], mesh.positions[v[1]], mesh.positions[v[2]], mesh.positions[v[3]]};
      const int s = quad_start(p);
      for (int k : {0, 1, 2, 0, 2, 3}) mesh.indices.push_back(v[(s + k) % 4]);
    }
    c += n;
  }
  return mesh;
}

}  // namespace

std::optional<Scene> read_simple_obj(const fs::path& path, std::string_view data, const LoadOptions& options) {
  ObjData d;
  d.reserve_for(data);
  const fs::path folder = asset_folder(path, options.asset_root);
  std::size_t pos = 0;
  while (pos < data.size()) {
    std::string_view line = next_line(data, pos);
    if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    if (!line.empty() && line.back() == '\\') return std::nullopt;  // continued lines: assimp's reading
    if (!d.read_line(path, folder, line)) return std::nullopt;
  }
  if (d.face_sizes.empty() || !d.forward_indices_in_range()) return std::nullopt;
  Vec3 albedo = Mesh{}.albedo;
  if (!d.material.empty() && !material_colour(path, d.libraries, d.material, albedo)) return std::nullopt;

  const bool has_uv = d.form == kVT || d.form == kVTN;
  if (options.uv_set > 0)
    throw InputError(path.string() + ": has " + std::string(has_uv ? "1 UV set" : "0 UV sets") + ", --uv-set " + std::to_string(options.uv_set) +
                     " asked for");
  Mesh mesh = weld_and_triangulate(d);
  mesh.albedo = albedo;
  return io_detail::one_mesh_scene(path, std::move(mesh));
}

}  // namespace ao
