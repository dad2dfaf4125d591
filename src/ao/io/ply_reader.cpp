// SPDX-License-Identifier: Apache-2.0
// PLY reader. assimp 5.2's PLY path failed the SPEC's bad-input rules (a file cut inside its header
// loops forever, a header claiming 3e9 vertices ends in bad_alloc, a list count of 4294967295
// allocates 16 GB, an ASCII file missing its last faces loads with invented ones, a damaged
// "property" line aborts in an assertion) and took about 400 bytes and 3-4 us per triangle on big
// binary files. This reader parses the header, checks the declared counts against the data size,
// then reads each element once, straight into the final arrays.
#include "ao/io/ply_reader.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "ao/core/error.h"
#include "ao/io/io_error_internal.h"
#include "ao/io/number_text.h"

namespace ao {
namespace {

namespace fs = std::filesystem;

using io_detail::fail;
using io_detail::printable;
using io_detail::quote;

std::string_view next_token(std::string_view line, std::size_t& pos) {
  while (pos < line.size() && std::isspace(static_cast<unsigned char>(line[pos]))) ++pos;
  const std::size_t start = pos;
  while (pos < line.size() && !std::isspace(static_cast<unsigned char>(line[pos]))) ++pos;
  return line.substr(start, pos - start);
}

enum class Type { None, I8, U8, I16, U16, I32, U32, F32, F64 };

Type parse_type(std::string_view t) {
  if (t == "char" || t == "int8") return Type::I8;
  if (t == "uchar" || t == "uint8") return Type::U8;
  if (t == "short" || t == "int16") return Type::I16;
  if (t == "ushort" || t == "uint16") return Type::U16;
  if (t == "int" || t == "int32") return Type::I32;
  if (t == "uint" || t == "uint32") return Type::U32;
  if (t == "float" || t == "float32") return Type::F32;
  if (t == "double" || t == "float64") return Type::F64;
  return Type::None;
}

int type_size(Type t) {
  switch (t) {
    case Type::I8: case Type::U8: return 1;
    case Type::I16: case Type::U16: return 2;
    case Type::I32: case Type::U32: case Type::F32: return 4;
    case Type::F64: return 8;
    default: return 0;
  }
}

bool is_float(Type t) { return t == Type::F32 || t == Type::F64; }

/// Binary scalar at p, in the file's byte order.
template <bool BigEndian>
double load(const char* p, Type t) {
  unsigned char b[8];
  const int n = type_size(t);
  if constexpr (BigEndian) {
    for (int k = 0; k < n; ++k) b[k] = static_cast<unsigned char>(p[n - 1 - k]);
  } else {
    std::memcpy(b, p, static_cast<std::size_t>(n));
  }
  switch (t) {
    case Type::I8: return static_cast<std::int8_t>(b[0]);
    case Type::U8: return b[0];
    case Type::I16: { std::int16_t v; std::memcpy(&v, b, 2); return v; }
    case Type::U16: { std::uint16_t v; std::memcpy(&v, b, 2); return v; }
    case Type::I32: { std::int32_t v; std::memcpy(&v, b, 4); return v; }
    case Type::U32: { std::uint32_t v; std::memcpy(&v, b, 4); return v; }
    case Type::F32: { float v; std::memcpy(&v, b, 4); return v; }
    case Type::F64: { double v; std::memcpy(&v, b, 8); return v; }
    default: return 0;
  }
}

/// Where a vertex property goes.
enum Slot { kX, kY, kZ, kNx, kNy, kNz, kU, kV, kSlots, kSkip = kSlots };

struct Property {
  std::string name;
  bool is_list = false;
  Type count_type = Type::None;  ///< Lists only.
  Type type = Type::None;        ///< The scalar, or each list item.
  int slot = kSkip;              ///< Vertex properties only.
};

struct Element {
  std::string name;
  long long count = 0;
  long long min_bytes = 0;  ///< Smallest possible size of one element in this file's encoding.
  std::vector<Property> properties;
};

struct Header {
  std::string format;
  std::vector<Element> elements;
  std::size_t body_start = 0;
};

/// Where the line "end_header" starts and where the body after it starts; npos when there is no
/// such line. Lines are read whole, so a long comment (exporters write whole licences there) is
/// one line, and "end_header" inside a comment ends nothing. Linear in the header's length.
std::pair<std::size_t, std::size_t> find_end_header(std::string_view data) {
  for (std::size_t pos = 0; pos < data.size();) {
    const std::size_t end = std::min(data.find('\n', pos), data.size());
    std::size_t token = pos;
    const std::string_view key = next_token(data.substr(0, end), token);
    if (key == "end_header") return {pos, std::min(end + 1, data.size())};
    pos = end + 1;
  }
  return {std::string_view::npos, std::string_view::npos};
}

Header parse_header(const fs::path& path, std::string_view data) {
  const auto [header_end, body_start] = find_end_header(data);
  if (header_end == std::string_view::npos) fail(path, "truncated or malformed PLY header: no end_header line");
  Header h;
  std::string_view head = data.substr(0, header_end);
  int line_number = 0;
  while (!head.empty()) {
    const std::size_t end = std::min(head.find('\n'), head.size());
    const std::string_view line = head.substr(0, end);
    head.remove_prefix(std::min(end + 1, head.size()));
    ++line_number;
    std::size_t pos = 0;
    const std::string_view key = next_token(line, pos);
    const std::string at = "PLY header line " + std::to_string(line_number);
    if (key.empty() || key == "ply" || key == "comment" || key == "obj_info") continue;
    if (key == "format") {
      h.format = std::string(next_token(line, pos));
    } else if (key == "element") {
      Element e;
      const std::string_view name = next_token(line, pos), count = next_token(line, pos);
      const auto [ptr, ec] = std::from_chars(count.data(), count.data() + count.size(), e.count);
      if (name.empty() || ec != std::errc() || ptr != count.data() + count.size() || e.count < 0) fail(path, at + ": malformed element line");
      if (e.count > std::numeric_limits<std::uint32_t>::max()) fail(path, at + ": absurd element count " + quote(count));
      e.name = printable(name);
      h.elements.push_back(std::move(e));
    } else if (key == "property") {
      if (h.elements.empty()) fail(path, at + ": property before any element");
      Property prop;
      const std::string_view first = next_token(line, pos);
      prop.is_list = first == "list";
      if (prop.is_list) {
        prop.count_type = parse_type(next_token(line, pos));
        prop.type = parse_type(next_token(line, pos));
        if (prop.count_type == Type::None || is_float(prop.count_type) || prop.type == Type::None) fail(path, at + ": malformed list property");
      } else {
        prop.type = parse_type(first);
        if (prop.type == Type::None) fail(path, at + ": malformed property line");
      }
      const std::string_view name = next_token(line, pos);
      if (name.empty()) fail(path, at + ": property without a name");
      prop.name = std::string(name);
      // ASCII: each value takes at least a digit and a separator. Binary: a list takes at least its
      // count, a scalar its size.
      h.elements.back().min_bytes += h.format == "ascii" ? 2 : type_size(prop.is_list ? prop.count_type : prop.type);
      h.elements.back().properties.push_back(std::move(prop));
    } else {
      // A damaged "property" line would shift every value after it: a damaged header is an error.
      fail(path, at + ": unknown keyword " + quote(key));
    }
  }
  if (h.format != "ascii" && h.format != "binary_little_endian" && h.format != "binary_big_endian")
    fail(path, "PLY header has no valid format line");
  h.body_start = body_start;
  return h;
}

/// The vertex and face elements' roles, found by name.
struct Layout {
  int vertex = -1, face = -1;  ///< Element indices.
  int face_list = -1;          ///< Property index of the face's index list.
  bool normals = false, uvs = false;
};

Layout find_layout(const fs::path& path, Header& h) {
  Layout l;
  for (std::size_t i = 0; i < h.elements.size(); ++i) {
    if (h.elements[i].name == "vertex" && l.vertex < 0) l.vertex = static_cast<int>(i);
    if (h.elements[i].name == "face" && l.face < 0) l.face = static_cast<int>(i);
  }
  if (l.vertex < 0) fail(path, "the PLY file has no 'vertex' element");
  if (l.face < 0) fail(path, "the PLY file has no 'face' element: no triangles");
  Element& v = h.elements[static_cast<std::size_t>(l.vertex)];
  int found[kSlots];
  std::fill(found, found + kSlots, -1);
  for (std::size_t p = 0; p < v.properties.size(); ++p) {
    const Property& prop = v.properties[p];
    if (prop.is_list) continue;
    const std::string& n = prop.name;
    int slot = kSkip;
    if (n == "x") slot = kX;
    else if (n == "y") slot = kY;
    else if (n == "z") slot = kZ;
    else if (n == "nx") slot = kNx;
    else if (n == "ny") slot = kNy;
    else if (n == "nz") slot = kNz;
    else if (n == "u" || n == "s" || n == "texture_u" || n == "texture_s") slot = kU;
    else if (n == "v" || n == "t" || n == "texture_v" || n == "texture_t") slot = kV;
    if (slot != kSkip && found[slot] < 0) found[slot] = static_cast<int>(p);
  }
  for (int s : {kX, kY, kZ})
    if (found[s] < 0) fail(path, std::string("the PLY 'vertex' element has no '") + "xyz"[s] + "' property");
  l.normals = found[kNx] >= 0 && found[kNy] >= 0 && found[kNz] >= 0;
  l.uvs = found[kU] >= 0 && found[kV] >= 0;
  for (int s = 0; s < kSlots; ++s) {
    const bool used = s <= kZ || (s <= kNz ? l.normals : l.uvs);
    if (used) v.properties[static_cast<std::size_t>(found[s])].slot = s;
  }
  const Element& f = h.elements[static_cast<std::size_t>(l.face)];
  for (std::size_t p = 0; p < f.properties.size() && l.face_list < 0; ++p)
    if (f.properties[p].is_list && (f.properties[p].name == "vertex_indices" || f.properties[p].name == "vertex_index")) l.face_list = static_cast<int>(p);
  if (l.face_list < 0) fail(path, "the PLY 'face' element has no vertex_indices list");
  if (is_float(f.properties[static_cast<std::size_t>(l.face_list)].type)) fail(path, "the PLY face indices are floating point, not integers");
  return l;
}

/// Output arrays and the per-face work shared by the ASCII and binary paths.
class Builder {
 public:
  Builder(const fs::path& path, const Layout& layout, long long vertices, long long faces, long long max_triangles)
      : path_(path), vertex_count_(vertices) {
    mesh_.name = path.stem().string();
    // kVertexPadding spare: validate_and_prepare then keeps this array, and the BVH shares it.
    mesh_.positions.reserve(static_cast<std::size_t>(vertices) + kVertexPadding);
    mesh_.positions.resize(static_cast<std::size_t>(vertices));
    if (layout.normals) mesh_.normals.resize(static_cast<std::size_t>(vertices));
    if (layout.uvs) mesh_.uvs.resize(static_cast<std::size_t>(vertices));
    // Most files hold triangles; the reservation is bounded by what the data can hold.
    mesh_.indices.reserve(3 * static_cast<std::size_t>(std::min(faces, max_triangles)));
  }

  void set(long long v, int slot, float f) {
    const auto i = static_cast<std::size_t>(v);
    switch (slot) {
      case kX: mesh_.positions[i].x = f; break;
      case kY: mesh_.positions[i].y = f; break;
      case kZ: mesh_.positions[i].z = f; break;
      case kNx: mesh_.normals[i].x = f; break;
      case kNy: mesh_.normals[i].y = f; break;
      case kNz: mesh_.normals[i].z = f; break;
      case kU: mesh_.uvs[i].x = f; break;
      case kV: mesh_.uvs[i].y = f; break;
      default: break;
    }
  }

  /// Index k of face f; call face_done after the last.
  void corner(long long f, long long index) {
    if (index < 0 || index >= vertex_count_)
      fail(path_, "face " + std::to_string(f) + " uses vertex " + std::to_string(index) + ", the file has " + std::to_string(vertex_count_));
    const auto i = static_cast<std::uint32_t>(index);
    // Fan triangulation keeps the face's winding.
    if (corners_ == 0) first_ = i;
    else if (corners_ >= 2) {
      mesh_.indices.push_back(first_);
      mesh_.indices.push_back(previous_);
      mesh_.indices.push_back(i);
    }
    previous_ = i;
    ++corners_;
  }
  void face_done(long long f) {
    if (corners_ < 3) fail(path_, "face " + std::to_string(f) + " has " + std::to_string(corners_) + " vertices, at least 3 are needed");
    corners_ = 0;
  }

  Mesh take() { return std::move(mesh_); }
  std::vector<std::uint32_t>& indices() { return mesh_.indices; }
  long long vertex_count() const { return vertex_count_; }

 private:
  const fs::path& path_;
  long long vertex_count_;
  Mesh mesh_;
  long long corners_ = 0;
  std::uint32_t first_ = 0, previous_ = 0;
};

std::string element_summary(const Header& h) {
  std::string summary;
  for (const Element& el : h.elements) summary += (summary.empty() ? "" : ", ") + std::to_string(el.count) + " x '" + el.name + "'";
  return summary;
}

std::string truncated(const Header& h, const Element& e, long long i) {
  return "truncated: header declares " + element_summary(h) + " elements, the data ends in '" + e.name + "' " + std::to_string(i);
}

/// Data after the last element the header declares, other than blank space, means the header's
/// counts are short: reading only what they say would drop elements (faces) without a word.
void check_nothing_after(const fs::path& path, const Header& h, std::string_view rest, const std::string& where) {
  if (rest.find_first_not_of(" \t\r\n") == std::string_view::npos) return;
  fail(path, "the header declares " + element_summary(h) + " elements, but the data holds more after the last of them (" + where + ")");
}

/// The usual binary little-endian face element, a byte count and three 32-bit indices per face
/// with nothing else (13 bytes a face), read in parallel straight into the index array. Returns
/// false, having written nothing, when the element has another layout or any face is not such a
/// triangle with indices in range; the general reader then reads it, and reports the problem.
/// Every face is checked to start with the count 3, so by induction face i starts at byte 13 i.
bool read_triangles_fast(const Element& e, const Layout& l, const char* p, const char* end, Builder& out) {
  if (e.properties.size() != 1 || l.face_list != 0) return false;
  const Property& q = e.properties[0];
  if (!q.is_list || (q.count_type != Type::U8 && q.count_type != Type::I8) || (q.type != Type::I32 && q.type != Type::U32)) return false;
  constexpr long long kFace = 13;
  if (e.count > (end - p) / kFace) return false;
  const auto faces = static_cast<std::size_t>(e.count);
  std::vector<std::uint32_t>& indices = out.indices();
  if (!indices.empty() || indices.capacity() < 3 * faces) return false;
  indices.resize(3 * faces);
  // Indices are compared as unsigned: a negative int32 becomes >= 2^31 and is out of range too.
  const auto vertex_count = static_cast<std::uint64_t>(out.vertex_count());
  const bool ok = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, faces, 1 << 15), true,
      [&](const tbb::blocked_range<std::size_t>& r, bool good) {
        if (!good) return false;
        for (std::size_t f = r.begin(); f < r.end(); ++f) {
          const char* const face = p + f * kFace;
          if (face[0] != 3) return false;
          std::uint32_t i[3];
          std::memcpy(i, face + 1, sizeof i);
          if (i[0] >= vertex_count || i[1] >= vertex_count || i[2] >= vertex_count) return false;
          std::memcpy(&indices[3 * f], i, sizeof i);
        }
        return true;
      },
      [](bool a, bool b) { return a && b; });
  if (!ok) indices.clear();
  return ok;
}

/// The vertex element when no property is a list: only the properties that are used, at their
/// offsets in the fixed-size record; records are independent, so read in parallel.
template <bool BigEndian>
void read_fixed_vertices(const Element& e, const char* first, Builder& out) {
  struct Field {
    long long offset;
    Type type;
    int slot;
  };
  std::vector<Field> fields;
  long long offset = 0;
  for (const Property& q : e.properties) {
    if (q.slot != kSkip) fields.push_back({offset, q.type, q.slot});
    offset += type_size(q.type);
  }
  const long long stride = e.min_bytes;
  tbb::parallel_for(tbb::blocked_range<long long>(0, e.count, 1 << 15), [&](const tbb::blocked_range<long long>& r) {
    for (long long i = r.begin(); i < r.end(); ++i) {
      const char* const record = first + i * stride;
      for (const Field& f : fields) {
        float value;
        if (!BigEndian && f.type == Type::F32) std::memcpy(&value, record + f.offset, 4);  // the common case, without conversion
        else value = static_cast<float>(load<BigEndian>(record + f.offset, f.type));
        out.set(i, f.slot, value);
      }
    }
  });
}

/// An element with list properties, record by record from `p`, every read bounded by `end`;
/// returns where the element ends.
template <bool BigEndian>
const char* read_listed_element(const fs::path& path, const Header& h, const Layout& l, const Element& e, bool is_vertex, bool is_face,
                                const char* p, const char* const end, Builder& out) {
  for (long long i = 0; i < e.count; ++i) {
    for (std::size_t pi = 0; pi < e.properties.size(); ++pi) {
      const Property& q = e.properties[pi];
      const int size = type_size(q.type);
      if (!q.is_list) {
        if (end - p < size) fail(path, truncated(h, e, i));
        if (is_vertex && q.slot != kSkip) out.set(i, q.slot, static_cast<float>(load<BigEndian>(p, q.type)));
        p += size;
        continue;
      }
      const int count_size = type_size(q.count_type);
      if (end - p < count_size) fail(path, truncated(h, e, i));
      const double n_value = load<BigEndian>(p, q.count_type);
      p += count_size;
      if (n_value < 0) fail(path, "'" + e.name + "' " + std::to_string(i) + " has a negative list count " + std::to_string(static_cast<long long>(n_value)));
      const auto n = static_cast<long long>(n_value);
      // The list must fit in what is left: a damaged count cannot make us read past the end.
      if (n > (end - p) / size) fail(path, truncated(h, e, i));
      if (is_face && static_cast<int>(pi) == l.face_list) {
        if (!BigEndian && (q.type == Type::I32 || q.type == Type::U32)) {
          // The common case, without conversion through double.
          for (long long k = 0; k < n; ++k, p += 4) {
            std::uint32_t u;
            std::memcpy(&u, p, 4);
            out.corner(i, q.type == Type::I32 ? static_cast<long long>(static_cast<std::int32_t>(u)) : static_cast<long long>(u));
          }
        } else {
          for (long long k = 0; k < n; ++k, p += size) out.corner(i, static_cast<long long>(load<BigEndian>(p, q.type)));
        }
      } else {
        p += n * size;
      }
    }
    if (is_face) out.face_done(i);
  }
  return p;
}

template <bool BigEndian>
void read_binary(const fs::path& path, const Header& h, const Layout& l, std::string_view body, Builder& out) {
  const char* p = body.data();
  const char* const end = body.data() + body.size();
  for (std::size_t ei = 0; ei < h.elements.size(); ++ei) {
    const Element& e = h.elements[ei];
    const bool is_vertex = static_cast<int>(ei) == l.vertex, is_face = static_cast<int>(ei) == l.face;
    const bool fixed = std::none_of(e.properties.begin(), e.properties.end(), [](const Property& q) { return q.is_list; });
    if (fixed) {
      // Fixed-size elements: one bounds check for the whole element (min_bytes is the size here).
      // The face element has a list, so it is never fixed-size.
      if (e.count * e.min_bytes > end - p) fail(path, truncated(h, e, (end - p) / std::max(1LL, e.min_bytes)));
      if (is_vertex) read_fixed_vertices<BigEndian>(e, p, out);
      p += e.count * e.min_bytes;
    } else if (is_face && !BigEndian && read_triangles_fast(e, l, p, end, out)) {
      p += e.count * 13;
    } else {
      p = read_listed_element<BigEndian>(path, h, l, e, is_vertex, is_face, p, end, out);
    }
  }
  check_nothing_after(path, h, std::string_view(p, static_cast<std::size_t>(end - p)), std::to_string(end - p) + " more bytes");
}

void read_ascii(const fs::path& path, const Header& h, const Layout& l, std::string_view body, Builder& out) {
  std::size_t pos = 0;
  long long line_number = 0;
  for (std::size_t ei = 0; ei < h.elements.size(); ++ei) {
    const Element& e = h.elements[ei];
    if (e.properties.empty()) continue;
    const bool is_vertex = static_cast<int>(ei) == l.vertex, is_face = static_cast<int>(ei) == l.face;
    for (long long i = 0; i < e.count; ++i) {
      // One element per line; blank lines are skipped.
      std::string_view line;
      do {
        if (pos >= body.size()) fail(path, truncated(h, e, i));
        const std::size_t end = std::min(body.find('\n', pos), body.size());
        line = body.substr(pos, end - pos);
        pos = end + 1;
        ++line_number;
      } while (line.find_first_not_of(" \t\r") == std::string_view::npos);
      const std::string at = "data line " + std::to_string(line_number) + " ('" + e.name + "' " + std::to_string(i) + ")";
      std::size_t lp = 0;
      const auto number = [&](double& value) {
        std::string_view token = next_token(line, lp);
        if (token.empty()) return false;
        // Beyond double's range reads as infinity (reported by validation) or 0 (number_text.h).
        if (!parse_real(token, value)) fail(path, at + ": " + quote(token) + " is not a number");
        return true;
      };
      for (std::size_t pi = 0; pi < e.properties.size(); ++pi) {
        const Property& q = e.properties[pi];
        double value = 0;
        if (!q.is_list) {
          if (!number(value)) fail(path, at + ": expects " + std::to_string(e.properties.size()) + " values, the line has fewer");
          if (is_vertex && q.slot != kSkip) out.set(i, q.slot, narrow_to_float(value));
          continue;
        }
        if (!number(value) || value < 0 || value != std::floor(value)) fail(path, at + ": missing or bad list count");
        const auto n = static_cast<long long>(value);
        // Values take at least two characters each: the line bounds what a count may claim.
        if (n > static_cast<long long>(line.size() - lp + 1) / 2) {
          long long rest = 0;
          for (std::size_t k = lp; !next_token(line, k).empty();) ++rest;
          fail(path, at + ": expects " + std::to_string(n) + " more values, the line has " + std::to_string(rest));
        }
        const bool indices = is_face && static_cast<int>(pi) == l.face_list;
        for (long long k = 0; k < n; ++k) {
          if (!number(value)) fail(path, at + ": expects " + std::to_string(n) + " values in its list, the line has " + std::to_string(k));
          if (indices) {
            if (value != std::floor(value)) fail(path, at + ": vertex index " + std::to_string(value) + " is not an integer");
            out.corner(i, static_cast<long long>(std::clamp(value, -1e18, 1e18)));  // clamped: the cast stays defined
          }
        }
      }
      if (is_face) out.face_done(i);
    }
  }
  check_nothing_after(path, h, body.substr(std::min(pos, body.size())), "after data line " + std::to_string(line_number));
}

}  // namespace

bool looks_like_ply(std::string_view data) { return data.starts_with("ply\n") || data.starts_with("ply\r\n") || data.starts_with("PLY\n"); }

Scene read_ply(const fs::path& path, std::string_view data) {
  Header h = parse_header(path, data);
  const std::string_view body = data.substr(h.body_start);
  long long min_bytes = 0;
  std::string summary;
  for (const Element& e : h.elements) {
    min_bytes += e.count * e.min_bytes;  // < 2^32 x 2^16 properties x 8 bytes at most: no overflow
    summary += (summary.empty() ? "" : ", ") + std::to_string(e.count) + " x '" + e.name + "'";
  }
  if (min_bytes > static_cast<long long>(body.size()))
    fail(path, "header declares " + summary + " elements but the data has only " + std::to_string(body.size()) + " bytes");
  const Layout l = find_layout(path, h);
  const Element& v = h.elements[static_cast<std::size_t>(l.vertex)];
  const Element& f = h.elements[static_cast<std::size_t>(l.face)];
  // A triangle takes at least its count and three indices (binary) or "3 0 0 0\n" (8 characters).
  const Property& list = f.properties[static_cast<std::size_t>(l.face_list)];
  const long long triangle_bytes = h.format == "ascii" ? 8 : type_size(list.count_type) + 3 * type_size(list.type);
  Builder out(path, l, v.count, f.count, static_cast<long long>(body.size()) / triangle_bytes + 1);
  if (h.format == "ascii") read_ascii(path, h, l, body, out);
  else if (h.format == "binary_big_endian") read_binary<true>(path, h, l, body, out);
  else read_binary<false>(path, h, l, body, out);

  Scene scene;
  scene.name = path.filename().string();
  scene.meshes.push_back(out.take());
  return scene;
}

}  // namespace ao
