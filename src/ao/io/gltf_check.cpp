// SPDX-License-Identifier: Apache-2.0
// glTF 2.0 / GLB structure check, run before assimp. Measured with libassimp 5.2.5 (mutation
// fuzzing of small files):
//  - JSON nested ~175,000 levels deep, or a node chain ~17,500 deep, overflows the stack (its JSON
//    parser and its node import both recurse): limits kMaxGltfJsonDepth and kMaxGltfNodeDepth.
//  - A 53 KB GLB whose JSON chunk length says 0xFFFFFFF0 takes 4.2 GB and half a minute before its
//    error: every GLB length is checked against the file size first.
//  - An index past the vertex count drops the triangle silently; a VEC2 POSITION accessor or a
//    byteStride smaller than the element reads garbage: accessors are checked against their
//    bufferViews, and index values against the vertex count.
// The JSON is parsed with nlohmann-json, whose parser is iterative; a callback stops it at the
// depth limit, so the check itself cannot overflow the stack.
#include "ao/io/gltf_check.h"

#include <nlohmann/json.hpp>

#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "ao/core/error.h"
#include "ao/io/asset_path.h"
#include "ao/io/io_error_internal.h"
#include "ao/io/json_text.h"

namespace ao {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using io_detail::fail;
using io_detail::one_line;

std::uint32_t read_u32(const char* p) {
  const auto* b = reinterpret_cast<const unsigned char*>(p);
  return static_cast<std::uint32_t>(b[0]) | static_cast<std::uint32_t>(b[1]) << 8 | static_cast<std::uint32_t>(b[2]) << 16 |
         static_cast<std::uint32_t>(b[3]) << 24;
}

constexpr std::uint32_t kGlbMagic = 0x46546C67;  // "glTF"
constexpr std::uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
constexpr std::uint32_t kChunkBin = 0x004E4942;   // "BIN\0"

struct GlbChunks {
  std::string_view json;
  std::optional<std::string_view> bin;
};

/// GLB 2: a 12-byte header (magic, version, total length), then chunks of (length, type, data):
/// JSON first, then at most one BIN, then chunks of other types, which are ignored (glTF 2.0
/// spec, "Binary glTF Layout"). Every length is checked against what the file holds before
/// anything uses it, and the chunks must fill the file exactly, as the header's length says.
GlbChunks split_glb(const fs::path& path, std::string_view data) {
  if (data.size() < 12) fail(path, "truncated GLB: " + std::to_string(data.size()) + " bytes, the header alone takes 12");
  const std::uint32_t version = read_u32(data.data() + 4), length = read_u32(data.data() + 8);
  if (version != 2) fail(path, "GLB version " + std::to_string(version) + " is not supported, only version 2 (glTF 2.0)");
  if (length != data.size())
    fail(path, "GLB header says the file has " + std::to_string(length) + " bytes, it has " + std::to_string(data.size()));
  const std::string_view all = data.substr(0, length);
  if (all.size() < 20) fail(path, "truncated GLB: no JSON chunk");
  const std::uint32_t json_length = read_u32(all.data() + 12), json_type = read_u32(all.data() + 16);
  if (json_type != kChunkJson) fail(path, "the first GLB chunk is not JSON");
  if (json_length > all.size() - 20)
    fail(path, "GLB JSON chunk says " + std::to_string(json_length) + " bytes, only " + std::to_string(all.size() - 20) + " follow");
  GlbChunks chunks{all.substr(20, json_length), std::nullopt};
  std::size_t pos = 20 + static_cast<std::size_t>(json_length);
  for (int k = 1; pos < all.size(); ++k) {
    if (all.size() - pos < 8)
      fail(path, "GLB has " + std::to_string(all.size() - pos) + " bytes after chunk " + std::to_string(k - 1) + ", too few for another chunk's 8-byte header");
    const std::uint32_t chunk_length = read_u32(all.data() + pos), type = read_u32(all.data() + pos + 4);
    if (chunk_length > all.size() - pos - 8)
      fail(path, "GLB chunk " + std::to_string(k) + " says " + std::to_string(chunk_length) + " bytes, only " + std::to_string(all.size() - pos - 8) + " follow");
    if (type == kChunkBin) {
      if (k != 1) fail(path, "GLB chunk " + std::to_string(k) + " is a second binary chunk or follows another chunk; only chunk 1 may be BIN");
      chunks.bin = all.substr(pos + 8, chunk_length);
    }
    pos += 8 + static_cast<std::size_t>(chunk_length);
  }
  return chunks;
}

json parse_json(const fs::path& path, std::string_view text) {
  try {
    return parse_json_with_depth_limit(text, kMaxGltfJsonDepth);  // linear in the text, the depth checked as it opens
  } catch (const JsonTooDeep&) {
    fail(path, "glTF JSON nests deeper than " + std::to_string(kMaxGltfJsonDepth) + " levels");
  } catch (const JsonDuplicateKey& e) {
    fail(path, "glTF JSON has the key '" + one_line(e.key) + "' twice in one object (readers differ on which counts)");
  } catch (const json::parse_error& e) {
    // nlohmann's text names its own grammar; the byte where it stopped, and the text there, is
    // what a person can look at.
    if (e.byte >= text.size()) fail(path, "truncated glTF JSON: it ends inside a value (byte " + std::to_string(text.size()) + ")");
    const std::size_t at = e.byte > 0 ? e.byte - 1 : 0, from = at > 12 ? at - 12 : 0;
    fail(path, "malformed glTF JSON: unexpected text at byte " + std::to_string(e.byte) + " ('" + one_line(text.substr(from, std::min<std::size_t>(24, text.size() - from))) +
                   "')");
  } catch (const json::exception& e) {
    fail(path, "malformed or truncated glTF JSON (" + one_line(e.what()) + ")");
  }
}

int base64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+' || c == '-') return 62;
  if (c == '/' || c == '_') return 63;
  return -1;
}

/// Decodes base64; nullopt on a character outside the alphabet.
std::optional<std::string> decode_base64(std::string_view in) {
  while (!in.empty() && in.back() == '=') in.remove_suffix(1);
  std::string out;
  out.reserve(in.size() / 4 * 3 + 3);
  std::uint32_t acc = 0;
  int bits = 0;
  for (char c : in) {
    const int v = base64_value(c);
    if (v < 0) return std::nullopt;
    acc = (acc << 6) | static_cast<std::uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((acc >> bits) & 0xff);
    }
  }
  return out;
}

struct Accessor {
  std::uint64_t count = 0;
  int components = 0;
  int component_size = 0;
  int component_type = 0;
  std::string type;
  std::optional<std::size_t> view;
  std::uint64_t offset = 0;  ///< accessor.byteOffset
};

struct View {
  std::size_t buffer = 0;
  std::uint64_t offset = 0, length = 0, stride = 0;  ///< stride 0: tightly packed
};

class Checker {
 public:
  Checker(const fs::path& path, const json& root, std::optional<std::string_view> glb_bin, std::size_t file_size, fs::path folder)
      : path_(path), root_(root), glb_bin_(glb_bin), file_size_(file_size), folder_(std::move(folder)) {}

  void run() {
    if (!root_.is_object()) fail(path_, "glTF JSON is not an object");
    check_version();
    check_required_extensions();
    read_buffers();
    check_images();
    read_views();
    read_accessors();
    check_meshes();
    check_nodes();
    check_references();
  }

  /// When `obj` has `key`: it must be an array of `count` numbers (true); false when absent.
  bool numbers(const json& obj, const char* key, std::size_t count, const std::string& where) const {
    const auto it = obj.find(key);
    if (it == obj.end()) return false;
    bool ok = it->is_array() && it->size() == count;
    for (std::size_t k = 0; ok && k < count; ++k) ok = (*it)[k].is_number();
    if (!ok) bad(where + "." + key + " is not an array of " + std::to_string(count) + " numbers");
    return true;
  }

  /// The indices assimp follows without a word of its own ("GLTF: No scene", "Missing section"):
  /// the displayed scene, and each primitive's material.
  void check_references() {
    const json& scenes = array(root_, "scenes", "glTF");
    if (root_.contains("scene")) index(root_["scene"], scenes.size(), "scene", "scene");
    const json& materials = array(root_, "materials", "glTF");
    for (std::size_t i = 0; i < materials.size(); ++i) {
      const std::string where = "material " + std::to_string(i);
      const json& material = object(materials[i], where);
      const auto pbr = material.find("pbrMetallicRoughness");
      if (pbr != material.end()) numbers(object(*pbr, where + ".pbrMetallicRoughness"), "baseColorFactor", 4, where + ".pbrMetallicRoughness");
    }
    // A node's transform properties have fixed sizes; a reader that meets another size ignores
    // the property (the mesh lands elsewhere, or unscaled) without a word.
    const json& nodes = array(root_, "nodes", "glTF");
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      const std::string where = "node " + std::to_string(i);
      numbers(nodes[i], "matrix", 16, where);
      numbers(nodes[i], "translation", 3, where);
      numbers(nodes[i], "scale", 3, where);
      if (numbers(nodes[i], "rotation", 4, where)) {
        double len2 = 0;
        for (const json& q : nodes[i]["rotation"]) len2 += q.get<double>() * q.get<double>();
        // Exporters round unit quaternions to a few digits; a length off by more than 1% is not
        // a rotation (assimp would scale and shear by it, tinygltf-based readers normalise it).
        if (!(std::abs(std::sqrt(len2) - 1.0) <= 0.01))
          bad(where + ".rotation is not a unit quaternion (length " + std::to_string(std::sqrt(len2)) + ")");
      }
    }
    const json& meshes = array(root_, "meshes", "glTF");
    for (std::size_t m = 0; m < meshes.size(); ++m) {
      const json& primitives = array(meshes[m], "primitives", "mesh " + std::to_string(m));
      for (std::size_t p = 0; p < primitives.size(); ++p)
        if (primitives[p].contains("material"))
          index(primitives[p]["material"], materials.size(), "material", "mesh " + std::to_string(m) + " primitive " + std::to_string(p) + ".material");
    }
  }

 private:
  const fs::path& path_;
  const json& root_;
  std::optional<std::string_view> glb_bin_;
  std::size_t file_size_;
  fs::path folder_;                         // what external files must lie inside (asset_path.h)
  std::vector<std::string> owned_;          // decoded data URIs and external files
  std::vector<std::string_view> buffers_;   // each buffer's bytes, byteLength long
  std::vector<View> views_;
  std::vector<Accessor> accessors_;
  std::vector<GltfSize::Counts> mesh_size_;  // per mesh, all its primitives

 public:
  GltfSize size_;

 private:
  [[noreturn]] void bad(const std::string& problem) const { fail(path_, problem); }

  const json& array(const json& obj, const char* key, const std::string& where) const {
    static const json empty = json::array();
    const auto it = obj.find(key);
    if (it == obj.end()) return empty;
    if (!it->is_array()) bad(where + "." + key + " is not an array");
    return *it;
  }

  const json& object(const json& value, const std::string& where) const {
    if (!value.is_object()) bad(where + " is not an object");
    return value;
  }

  /// The object member `key` of `obj`, which must be present.
  const json& member_object(const json& obj, const char* key, const std::string& where) const {
    const auto it = obj.find(key);
    if (it == obj.end()) bad(where + " has no " + key);
    return object(*it, where + "." + key);
  }

  /// A non-negative integer member (or `fallback` when absent and one is given).
  std::uint64_t uint(const json& obj, const char* key, const std::string& where, std::optional<std::uint64_t> fallback = std::nullopt) const {
    const auto it = obj.find(key);
    if (it == obj.end()) {
      if (!fallback) bad(where + " has no " + key);
      return *fallback;
    }
    if (!it->is_number_unsigned()) bad(where + "." + key + " is not a non-negative integer");
    return it->get<std::uint64_t>();
  }

  std::size_t index(const json& value, std::size_t size, const std::string& what, const std::string& where) const {
    if (!value.is_number_unsigned()) bad(where + " is not a valid " + what + " index");
    const std::uint64_t i = value.get<std::uint64_t>();
    if (i >= size) bad(where + " refers to " + what + " " + std::to_string(i) + ", the file has " + std::to_string(size));
    return static_cast<std::size_t>(i);
  }

  void check_version() {
    const auto asset = root_.find("asset");
    if (asset == root_.end() || !asset->is_object()) bad("not a glTF file: no \"asset\" object");
    const auto version = asset->find("version");
    if (version == asset->end() || !version->is_string()) bad("glTF asset has no version");
    const std::string v = version->get<std::string>();
    if (!v.starts_with("2.")) bad("glTF version '" + one_line(v.substr(0, 16)) + "' is not supported, only 2.0");
  }

  /// A reader must refuse a file that requires an extension it does not implement (glTF 2.0 spec,
  /// "Specifying Extensions"). ao reads geometry, node transforms, UVs and the base colour:
  /// extensions about materials, textures' images and sampling, lights and metadata leave those
  /// as they are; the others (compressed or quantized geometry, GPU instancing, unknown ones)
  /// would be misread.
  void check_required_extensions() {
    for (const json& e : array(root_, "extensionsRequired", "glTF")) {
      if (!e.is_string()) bad("extensionsRequired holds a value that is not an extension name");
      const std::string& name = e.get_ref<const std::string&>();
      if (name == "KHR_draco_mesh_compression" || name == "EXT_meshopt_compression")
        bad("its geometry is compressed with " + name + ", which ao cannot decode; export it uncompressed");
      const bool harmless = name.starts_with("KHR_materials_") || name == "KHR_texture_transform" || name == "KHR_texture_basisu" ||
                            name == "EXT_texture_webp" || name == "EXT_texture_avif" || name == "KHR_lights_punctual" || name == "KHR_xmp_json_ld";
      if (!harmless) bad("it requires the glTF extension '" + one_line(name, 64) + "', which ao does not read");
    }
  }

  void read_buffers() {
    const json& buffers = array(root_, "buffers", "glTF");
    owned_.reserve(buffers.size());
    for (std::size_t b = 0; b < buffers.size(); ++b) {
      const std::string where = "buffer " + std::to_string(b);
      const json& buffer = object(buffers[b], where);
      const std::uint64_t length = uint(buffer, "byteLength", where);
      std::string_view bytes;
      const auto uri = buffer.find("uri");
      if (uri == buffer.end()) {
        if (b != 0 || !glb_bin_) bad(where + " has no uri and is not a GLB's binary chunk");
        bytes = *glb_bin_;
      } else if (!uri->is_string()) {
        bad(where + ".uri is not a string");
      } else {
        bytes = load_uri(uri->get_ref<const std::string&>(), where);
      }
      if (bytes.size() < length)
        bad(where + " says " + std::to_string(length) + " bytes, its data has " + std::to_string(bytes.size()));
      buffers_.push_back(bytes.substr(0, static_cast<std::size_t>(length)));
    }
  }

  std::string_view load_uri(const std::string& uri, const std::string& where) {
    if (uri.starts_with("data:")) {
      const std::size_t comma = uri.find(',');
      if (comma == std::string::npos || std::string_view(uri).substr(0, comma).find(";base64") == std::string_view::npos)
        bad(where + ": only base64 data URIs are supported");
      // The media types glTF gives buffers (and that the document reader knows: another is read
      // as a file name).
      const std::string_view header = std::string_view(uri).substr(0, comma + 1);
      if (header != "data:application/octet-stream;base64," && header != "data:application/gltf-buffer;base64,")
        bad(where + ": a data URI of type '" + one_line(std::string(header.substr(5, std::min<std::size_t>(header.size() - 5, 48)))) +
            "'; glTF buffers are application/octet-stream or application/gltf-buffer");
      std::optional<std::string> decoded = decode_base64(std::string_view(uri).substr(comma + 1));
      if (!decoded) bad(where + ": the data URI is not valid base64");
      return owned_.emplace_back(std::move(*decoded));
    }
    if (uri.find("://") != std::string::npos) bad(where + ": external URL '" + one_line(uri.substr(0, 60)) + "' is not supported, only files");
    const fs::path file = resolve_asset_reference(path_, folder_, percent_decode(uri), where + ": its file");
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) bad(where + ": its file '" + one_line(uri.substr(0, 60)) + "' does not exist beside the glTF");
    std::ifstream in(file, std::ios::binary);
    std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) bad(where + ": cannot read its file '" + one_line(uri.substr(0, 60)) + "'");
    return owned_.emplace_back(std::move(content));
  }

  /// Images are not decoded here, but `ao bake --gltf` embeds the files they name in its GLB, and
  /// assimp may open them: a file URI must name a file inside the asset's folder, as buffers do.
  void check_images() {
    const json& images = array(root_, "images", "glTF");
    for (std::size_t i = 0; i < images.size(); ++i) {
      const std::string where = "image " + std::to_string(i);
      const json& image = object(images[i], where);
      const auto uri = image.find("uri");
      if (uri == image.end()) continue;
      if (!uri->is_string()) bad(where + ".uri is not a string");
      const std::string& text = uri->get_ref<const std::string&>();
      if (text.starts_with("data:")) continue;
      if (text.find("://") != std::string::npos) bad(where + ": external URL '" + one_line(text.substr(0, 60)) + "' is not supported, only files");
      resolve_asset_reference(path_, folder_, percent_decode(text), where + ": its file");
    }
  }

  void read_views() {
    const json& views = array(root_, "bufferViews", "glTF");
    for (std::size_t i = 0; i < views.size(); ++i) {
      const std::string where = "bufferView " + std::to_string(i);
      const json& v = object(views[i], where);
      View view;
      view.buffer = index(v.contains("buffer") ? v["buffer"] : json(), buffers_.size(), "buffer", where + ".buffer");
      view.offset = uint(v, "byteOffset", where, 0);
      view.length = uint(v, "byteLength", where);
      view.stride = uint(v, "byteStride", where, 0);
      const std::uint64_t size = buffers_[view.buffer].size();
      if (view.length > size || view.offset > size - view.length)
        bad(where + " spans bytes " + std::to_string(view.offset) + ".." + std::to_string(view.offset + view.length) + " of buffer " +
            std::to_string(view.buffer) + ", which has " + std::to_string(size));
      // glTF 2.0: byteStride, when defined, is in [4, 252].
      if (v.contains("byteStride") && (view.stride < 4 || view.stride > 252))
        bad(where + ".byteStride " + std::to_string(view.stride) + " is outside 4..252");
      views_.push_back(view);
    }
  }

  static int component_size(std::uint64_t type) {
    switch (type) {
      case 5120: case 5121: return 1;  // (unsigned) byte
      case 5122: case 5123: return 2;  // (unsigned) short
      case 5125: case 5126: return 4;  // unsigned int, float
      default: return 0;
    }
  }

  static int component_count(const std::string& type) {
    if (type == "SCALAR") return 1;
    if (type == "VEC2") return 2;
    if (type == "VEC3") return 3;
    if (type == "VEC4" || type == "MAT2") return 4;
    if (type == "MAT3") return 9;
    if (type == "MAT4") return 16;
    return 0;
  }

  static std::string describe(const Accessor& a) {
    static const char* const names[] = {"byte", "unsigned byte", "short", "unsigned short", "", "unsigned int", "float"};
    return a.type + " " + names[a.component_type - 5120];
  }

  /// Checks that `count` elements of `elem` bytes from `offset` in view `v` lie inside it.
  void check_span(std::size_t v, std::uint64_t offset, std::uint64_t count, std::uint64_t elem, const std::string& where) const {
    const View& view = views_[v];
    const std::uint64_t stride = view.stride ? view.stride : elem;
    if (view.stride && view.stride < elem)
      bad(where + " has " + std::to_string(elem) + "-byte elements but bufferView " + std::to_string(v) + " has byteStride " +
          std::to_string(view.stride));
    // count <= length first, so stride x count cannot overflow (stride <= 252, length < 2^56).
    if (count > view.length || offset > view.length || stride * (count - 1) + elem > view.length - offset)
      bad(where + ": " + std::to_string(count) + " elements of " + std::to_string(elem) + " bytes from byte " + std::to_string(offset) +
          " do not fit in bufferView " + std::to_string(v) + " (" + std::to_string(view.length) + " bytes)");
  }

  void read_accessors() {
    const json& accessors = array(root_, "accessors", "glTF");
    for (std::size_t i = 0; i < accessors.size(); ++i) {
      const std::string where = "accessor " + std::to_string(i);
      const json& a = object(accessors[i], where);
      Accessor acc;
      const std::uint64_t ct = uint(a, "componentType", where);
      acc.component_size = component_size(ct);
      if (acc.component_size == 0) bad(where + " has unknown componentType " + std::to_string(ct));
      acc.component_type = static_cast<int>(ct);
      const auto type = a.find("type");
      if (type == a.end() || !type->is_string() || component_count(type->get<std::string>()) == 0) bad(where + " has no valid type");
      acc.type = type->get<std::string>();
      acc.components = component_count(acc.type);
      acc.count = uint(a, "count", where);
      if (acc.count == 0) bad(where + " has count 0");
      acc.offset = uint(a, "byteOffset", where, 0);
      const std::uint64_t elem = static_cast<std::uint64_t>(acc.components) * static_cast<std::uint64_t>(acc.component_size);
      if (a.contains("bufferView")) {
        acc.view = index(a["bufferView"], views_.size(), "bufferView", where + ".bufferView");
        check_span(*acc.view, acc.offset, acc.count, elem, where);
      } else if (acc.count > file_size_) {
        // Without a bufferView the accessor is zeros, which a reader still allocates.
        bad(where + " has " + std::to_string(acc.count) + " elements and no data; more than the file's " + std::to_string(file_size_) +
            " bytes is refused");
      }
      if (a.contains("sparse")) check_sparse(object(a["sparse"], where + ".sparse"), acc, elem, where + " (sparse)");
      accessors_.push_back(acc);
    }
  }

  /// Reads unsigned integer element k of an accessor of unsigned byte/short/int SCALARs.
  std::uint32_t read_index(std::size_t v, std::uint64_t offset, int size, std::uint64_t k) const {
    const View& view = views_[v];
    const std::uint64_t stride = view.stride ? view.stride : static_cast<std::uint64_t>(size);
    const char* p = buffers_[view.buffer].data() + view.offset + offset + stride * k;
    if (size == 1) return static_cast<unsigned char>(*p);
    if (size == 2) return static_cast<std::uint32_t>(static_cast<unsigned char>(p[0]) | static_cast<unsigned char>(p[1]) << 8);
    return read_u32(p);
  }

  void check_sparse(const json& s, const Accessor& acc, std::uint64_t elem, const std::string& where) {
    const std::uint64_t count = uint(s, "count", where);
    if (count == 0 || count > acc.count)
      bad(where + " replaces " + std::to_string(count) + " elements of " + std::to_string(acc.count));
    const json& indices = member_object(s, "indices", where);
    const json& values = member_object(s, "values", where);
    const std::size_t iv = index(indices.contains("bufferView") ? indices["bufferView"] : json(), views_.size(), "bufferView", where + ".indices.bufferView");
    const std::uint64_t ioff = uint(indices, "byteOffset", where + ".indices", 0);
    const std::uint64_t ict = uint(indices, "componentType", where + ".indices");
    if (ict != 5121 && ict != 5123 && ict != 5125) bad(where + ".indices.componentType " + std::to_string(ict) + " is not an unsigned integer type");
    const int isize = component_size(ict);
    check_span(iv, ioff, count, static_cast<std::uint64_t>(isize), where + ".indices");
    const std::size_t vv = index(values.contains("bufferView") ? values["bufferView"] : json(), views_.size(), "bufferView", where + ".values.bufferView");
    check_span(vv, uint(values, "byteOffset", where + ".values", 0), count, elem, where + ".values");
    for (std::uint64_t k = 0; k < count; ++k) {
      const std::uint32_t i = read_index(iv, ioff, isize, k);
      if (i >= acc.count) bad(where + ": index " + std::to_string(k) + " is " + std::to_string(i) + ", the accessor has " + std::to_string(acc.count) + " elements");
    }
  }

  void check_meshes() {
    const json& meshes = array(root_, "meshes", "glTF");
    mesh_size_.assign(meshes.size(), {});
    for (std::size_t m = 0; m < meshes.size(); ++m) {
      const json& mesh = object(meshes[m], "mesh " + std::to_string(m));
      const json& primitives = array(mesh, "primitives", "mesh " + std::to_string(m));
      for (std::size_t p = 0; p < primitives.size(); ++p) {
        const std::string where = "mesh " + std::to_string(m) + " primitive " + std::to_string(p);
        const json& prim = object(primitives[p], where);
        check_primitive(prim, where);
        add_size(prim, mesh_size_[m]);
      }
      size_.stored.add(mesh_size_[m]);
    }
  }

  /// What a reader makes of a primitive: assimp copies every attribute of every vertex as 12 bytes
  /// (aiVector3D; colours 16) and every triangle as an aiFace (16 bytes) with its own 3 indices (a
  /// 12-byte allocation, 32 with malloc's header and rounding).
  void add_size(const json& prim, GltfSize::Counts& c) const {
    const json& attributes = prim["attributes"];
    const std::uint64_t vertices = accessors_[attributes["POSITION"].get<std::size_t>()].count;
    std::uint64_t per_vertex = 0;
    for (const auto& [name, value] : attributes.items()) per_vertex += name.starts_with("COLOR_") ? 16 : 12;
    std::uint64_t corners = vertices;
    if (prim.contains("indices")) corners = accessors_[prim["indices"].get<std::size_t>()].count;
    const std::uint64_t mode = prim.contains("mode") ? prim["mode"].get<std::uint64_t>() : 4;
    const std::uint64_t triangles = mode == 4 ? corners / 3 : (mode == 5 || mode == 6) && corners >= 3 ? corners - 2 : 0;
    c.vertices += vertices;
    c.triangles += triangles;
    c.bytes += vertices * per_vertex + triangles * (16 + 32);
  }

  void check_primitive(const json& prim, const std::string& where) {
    const json& attributes = member_object(prim, "attributes", where);
    if (!attributes.contains("POSITION")) bad(where + " has no POSITION attribute");
    const std::size_t pos = index(attributes["POSITION"], accessors_.size(), "accessor", where + " POSITION");
    const Accessor& positions = accessors_[pos];
    if (positions.type != "VEC3" || positions.component_type != 5126)
      bad(where + ": POSITION accessor " + std::to_string(pos) + " is " + describe(positions) + ", glTF requires VEC3 float");
    const std::uint64_t vertices = positions.count;
    for (const auto& [name, value] : attributes.items()) {
      const std::size_t a = index(value, accessors_.size(), "accessor", where + " " + name);
      const Accessor& acc = accessors_[a];
      if (acc.count != vertices)
        bad(where + ": " + name + " accessor " + std::to_string(a) + " has " + std::to_string(acc.count) + " elements, POSITION has " +
            std::to_string(vertices));
      if (name == "NORMAL" && (acc.type != "VEC3" || acc.component_type != 5126))
        bad(where + ": NORMAL accessor " + std::to_string(a) + " is " + describe(acc) + ", glTF requires VEC3 float");
      if (name.starts_with("TEXCOORD_") && (acc.type != "VEC2" || (acc.component_type != 5126 && acc.component_type != 5121 && acc.component_type != 5123)))
        bad(where + ": " + name + " accessor " + std::to_string(a) + " is " + describe(acc) + ", glTF requires VEC2 float, unsigned byte or unsigned short");
    }
    for (const json& target : array(prim, "targets", where)) {
      for (const auto& [name, value] : object(target, where + " morph target").items()) {
        const std::size_t a = index(value, accessors_.size(), "accessor", where + " morph target " + name);
        if (accessors_[a].count != vertices)
          bad(where + ": morph target " + name + " accessor " + std::to_string(a) + " has " + std::to_string(accessors_[a].count) +
              " elements, POSITION has " + std::to_string(vertices));
      }
    }
    if (prim.contains("mode")) {
      const std::uint64_t mode = uint(prim, "mode", where);
      if (mode > 6) bad(where + " has unknown mode " + std::to_string(mode));
    }
    if (!prim.contains("indices")) return;
    const std::size_t ia = index(prim["indices"], accessors_.size(), "accessor", where + " indices");
    const Accessor& indices = accessors_[ia];
    if (indices.type != "SCALAR" || (indices.component_type != 5121 && indices.component_type != 5123 && indices.component_type != 5125))
      bad(where + ": indices accessor " + std::to_string(ia) + " is " + describe(indices) + ", glTF requires unsigned byte, short or int SCALAR");
    if (!indices.view) {  // all zeros
      if (size_.indices_without_data.empty()) size_.indices_without_data = where + ", indices accessor " + std::to_string(ia);
      return;
    }
    for (std::uint64_t k = 0; k < indices.count; ++k) {
      const std::uint32_t i = read_index(*indices.view, indices.offset, indices.component_size, k);
      if (i >= vertices)
        bad(where + ": index " + std::to_string(k) + " of accessor " + std::to_string(ia) + " is " + std::to_string(i) + ", POSITION has " +
            std::to_string(vertices) + " vertices");
    }
  }

  void check_nodes() {
    const json& nodes = array(root_, "nodes", "glTF");
    const std::size_t n = nodes.size();
    constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
    std::vector<std::size_t> parent(n, kNone);
    for (std::size_t i = 0; i < n; ++i) {
      const std::string where = "node " + std::to_string(i);
      const json& node = object(nodes[i], where);
      for (const json& c : array(node, "children", where)) {
        const std::size_t child = index(c, n, "node", where + " child");
        if (child == i) bad(where + " is its own child");
        if (parent[child] != kNone)
          bad("node " + std::to_string(child) + " has two parents (nodes " + std::to_string(parent[child]) + " and " + std::to_string(i) + ")");
        parent[child] = i;
      }
    }
    // Depth of every node, walking up to a root or a node of known depth; a walk that meets its
    // own start again is a cycle. Each node is assigned once, so this is linear in the node count.
    std::vector<std::uint32_t> depth(n, 0);
    std::vector<std::size_t> chain;
    for (std::size_t i = 0; i < n; ++i) {
      chain.clear();
      std::size_t cur = i;
      while (cur != kNone && depth[cur] == 0) {
        chain.push_back(cur);
        if (chain.size() > n) bad("the node hierarchy has a cycle through node " + std::to_string(i));
        cur = parent[cur];
      }
      std::uint32_t d = cur == kNone ? 0 : depth[cur];
      for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
        depth[*it] = ++d;
        if (d > static_cast<std::uint32_t>(kMaxGltfNodeDepth))
          bad("node " + std::to_string(*it) + " lies more than " + std::to_string(kMaxGltfNodeDepth) + " levels deep in the node hierarchy, the limit");
      }
    }
    // Every node that uses a mesh places one copy of it (the graph is a forest: one parent each).
    for (std::size_t i = 0; i < n; ++i) {
      const auto mesh = nodes[i].find("mesh");
      if (mesh == nodes[i].end()) continue;
      const std::size_t m = index(*mesh, mesh_size_.size(), "mesh", "node " + std::to_string(i) + ".mesh");
      size_.world.add(mesh_size_[m]);
      ++size_.uses;
    }
    const json& scenes = array(root_, "scenes", "glTF");
    for (std::size_t s = 0; s < scenes.size(); ++s) {
      const std::string where = "scene " + std::to_string(s);
      std::vector<char> listed(n, 0);
      for (const json& r : array(object(scenes[s], where), "nodes", where)) {
        const std::size_t root = index(r, n, "node", where + " root");
        if (parent[root] != kNone) bad(where + " lists node " + std::to_string(root) + " as a root, but it is a child of node " + std::to_string(parent[root]));
        // glTF requires unique roots; a reader would place the node's meshes twice.
        if (listed[root]++) bad(where + " lists node " + std::to_string(root) + " twice");
      }
    }
  }
};

}  // namespace

bool looks_like_gltf(const fs::path& path, std::string_view data) {
  if (data.size() >= 4 && read_u32(data.data()) == kGlbMagic) return true;
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".gltf" || ext == ".glb") return true;
  const std::size_t start = data.find_first_not_of(" \t\r\n");
  return start != std::string_view::npos && data[start] == '{';
}

GltfSize check_gltf(const fs::path& path, std::string_view data, const fs::path& asset_root) {
  std::optional<std::string_view> bin;
  std::string_view text = data;
  if (data.size() >= 4 && read_u32(data.data()) == kGlbMagic) {
    const GlbChunks chunks = split_glb(path, data);
    text = chunks.json;
    bin = chunks.bin;
  }
  const json root = parse_json(path, text);
  Checker checker(path, root, bin, data.size(), asset_folder(path, asset_root));
  checker.run();
  return checker.size_;
}

}  // namespace ao
