// SPDX-License-Identifier: Apache-2.0
// GLB layout (glTF 2.0 spec, "Binary glTF Layout"): a 12-byte header (magic "glTF", version 2,
// total length), a JSON chunk padded with spaces to 4 bytes, and a BIN chunk padded with zeros.
// Every accessor's bufferView starts on a 4-byte boundary, as the spec requires for float/uint32.
#include "ao/io/gltf_export.h"

#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <set>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/io/atomic_file.h"
#include "ao/version.h"

namespace ao {

namespace {

void pad4(std::string& s, char c) {
  while (s.size() % 4) s.push_back(c);
}

template <class T>
void append_raw(std::string& bin, const T* data, std::size_t count) {
  bin.append(reinterpret_cast<const char*>(data), count * sizeof(T));
}

void put_u32(std::string& s, std::uint32_t v) {
  char b[4];
  std::memcpy(b, &v, 4);
  s.append(b, 4);
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

bool is_gltf_file(const std::filesystem::path& path) {
  const std::string ext = lower(path.extension().string());
  if (ext == ".gltf" || ext == ".glb") return true;
  std::ifstream in(path, std::ios::binary);
  char magic[4] = {};
  return in.read(magic, 4) && std::memcmp(magic, "glTF", 4) == 0;
}

namespace {

nlohmann::json fresh_material(const Mesh& m, std::size_t mi) {
  return {{"name", m.name.empty() ? "material" + std::to_string(mi) : m.name},
          {"pbrMetallicRoughness", {{"baseColorFactor", {m.albedo.x, m.albedo.y, m.albedo.z, 1.0}}, {"metallicFactor", 0.0}, {"roughnessFactor", 1.0}}}};
}

}  // namespace

namespace {

using nlohmann::json;

constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963, kFloat = 5126, kUnsignedInt = 5125;

/// The glTF document being written: the binary chunk and the arrays that index into it.
struct GlbBuilder {
  std::string bin;
  json views = json::array(), accessors = json::array(), meshes = json::array(), materials = json::array(), nodes = json::array();
  json images = json::array(), samplers = json::array(), textures = json::array();

  int add_view(std::size_t offset, std::size_t length, std::optional<int> target) {
    json v = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", length}};
    if (target) v["target"] = *target;
    views.push_back(v);
    return static_cast<int>(views.size() - 1);
  }

  /// `count` elements of T as one accessor of `type` (float VEC2/VEC3, or uint32 SCALAR indices)
  /// with `extra` fields (min/max); returns its index.
  template <class T>
  std::size_t add_accessor(const T* data, std::size_t count, const char* type, json extra = json::object()) {
    const bool indices = std::is_same_v<T, std::uint32_t>;
    const std::size_t off = bin.size();
    append_raw(bin, data, count);
    json a = {{"bufferView", add_view(off, bin.size() - off, indices ? kElementArrayBuffer : kArrayBuffer)},
              {"componentType", indices ? kUnsignedInt : kFloat},
              {"count", count},
              {"type", type}};
    a.update(extra);
    accessors.push_back(a);
    return accessors.size() - 1;
  }

  int add_image(const std::string& bytes, const std::string& mime) {
    const std::size_t off = bin.size();
    bin += bytes;
    images.push_back({{"bufferView", add_view(off, bytes.size(), std::nullopt)}, {"mimeType", mime}});
    pad4(bin, '\0');
    return static_cast<int>(images.size() - 1);
  }

  /// One mesh, its material (with the AO map as occlusion texture when it has UVs and there is
  /// one) and a node placing it; per-vertex AO as COLOR_0 = (V, V, V), linear: glTF multiplies
  /// the base colour by it.
  void add_mesh(const Mesh& m, std::size_t mi, const float* vertex_ao, int texture) {
    json attributes;
    const Bounds3 b = m.bounds();  // POSITION needs min/max (spec requirement)
    attributes["POSITION"] = add_accessor(m.positions.data(), m.positions.size(), "VEC3",
                                          {{"min", {b.lo.x, b.lo.y, b.lo.z}}, {"max", {b.hi.x, b.hi.y, b.hi.z}}});
    if (!m.normals.empty()) attributes["NORMAL"] = add_accessor(m.normals.data(), m.normals.size(), "VEC3");
    if (vertex_ao) {
      std::vector<Vec3> colour(m.positions.size());
      for (std::size_t v = 0; v < colour.size(); ++v) colour[v] = {vertex_ao[v], vertex_ao[v], vertex_ao[v]};
      attributes["COLOR_0"] = add_accessor(colour.data(), colour.size(), "VEC3");
    }
    const bool has_uv = !m.uvs.empty();
    if (has_uv) {
      std::vector<Vec2> uv = m.uvs;
      for (Vec2& t : uv) t.y = 1.0f - t.y;  // glTF's UV origin is the top-left corner of the image
      attributes["TEXCOORD_0"] = add_accessor(uv.data(), uv.size(), "VEC2");
    }
    const std::size_t index_accessor = add_accessor(m.indices.data(), m.indices.size(), "SCALAR");
    json material = fresh_material(m, mi);
    if (has_uv && texture >= 0) material["occlusionTexture"] = {{"index", texture}, {"texCoord", 0}, {"strength", 1.0}};
    materials.push_back(material);
    meshes.push_back({{"name", m.name}, {"primitives", {{{"attributes", attributes}, {"indices", index_accessor}, {"material", mi}, {"mode", 4}}}}});
    nodes.push_back({{"mesh", mi}, {"name", m.name}});
  }

  /// The GLB file: header, JSON chunk padded with spaces, BIN chunk padded with zeros.
  std::string glb() {
    json root = {{"asset", {{"version", "2.0"}, {"generator", "ao bake " AO_VERSION_STRING}}},
                 {"scene", 0},
                 {"buffers", {{{"byteLength", bin.size()}}}},
                 {"bufferViews", views},
                 {"accessors", accessors},
                 {"materials", materials},
                 {"meshes", meshes},
                 {"nodes", nodes}};
    json scene_nodes = json::array();
    for (std::size_t i = 0; i < nodes.size(); ++i) scene_nodes.push_back(i);
    root["scenes"] = {{{"nodes", scene_nodes}}};
    if (!images.empty()) root["images"] = images;
    if (!samplers.empty()) root["samplers"] = samplers;
    if (!textures.empty()) root["textures"] = textures;
    std::string js = root.dump();
    pad4(js, ' ');
    pad4(bin, '\0');
    std::string out;
    put_u32(out, 0x46546C67u);  // "glTF"
    put_u32(out, 2);
    put_u32(out, static_cast<std::uint32_t>(12 + 8 + js.size() + 8 + bin.size()));
    put_u32(out, static_cast<std::uint32_t>(js.size()));
    put_u32(out, 0x4E4F534Au);  // "JSON"
    out += js;
    put_u32(out, static_cast<std::uint32_t>(bin.size()));
    put_u32(out, 0x004E4942u);  // "BIN\0"
    out += bin;
    return out;
  }
};

}  // namespace

void write_ao_glb(const std::filesystem::path& path, const Scene& scene, const std::string& png, const std::vector<float>* vertex_ao) {
  if (vertex_ao && vertex_ao->size() != scene.vertex_count())
    throw InputError(path.string() + ": per-vertex AO has " + std::to_string(vertex_ao->size()) + " values for " + std::to_string(scene.vertex_count()) + " vertices");
  GlbBuilder glb;
  int texture = -1;
  if (!png.empty()) {
    // Linear minification with mipmaps (9987) and bilinear magnification (9729).
    glb.samplers.push_back({{"magFilter", 9729}, {"minFilter", 9987}});
    glb.textures.push_back({{"sampler", 0}, {"source", glb.add_image(png, "image/png")}});
    texture = 0;
  }
  std::size_t first_vertex = 0;  // of the current mesh in vertex_ao
  for (std::size_t mi = 0; mi < scene.meshes.size(); ++mi) {
    const Mesh& m = scene.meshes[mi];
    glb.add_mesh(m, mi, vertex_ao ? vertex_ao->data() + first_vertex : nullptr, texture);
    first_vertex += m.positions.size();
  }
  const std::string out = glb.glb();
  write_bytes_atomically(path, out);
}

}  // namespace ao
