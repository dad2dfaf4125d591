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
#include <set>

#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/io/atomic_file.h"

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

void write_ao_glb(const std::filesystem::path& path, const Scene& scene, const std::string& png, const std::vector<float>* vertex_ao) {
  if (vertex_ao && vertex_ao->size() != scene.vertex_count())
    throw InputError(path.string() + ": per-vertex AO has " + std::to_string(vertex_ao->size()) + " values for " + std::to_string(scene.vertex_count()) + " vertices");
  std::size_t first_vertex = 0;  // of the current mesh in vertex_ao
  using nlohmann::json;
  std::string bin;
  json views = json::array(), accessors = json::array(), meshes = json::array(), materials = json::array(), nodes = json::array();
  json images = json::array(), samplers = json::array(), textures = json::array();
  constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963, kFloat = 5126, kUnsignedInt = 5125;
  auto add_view = [&](std::size_t offset, std::size_t length, std::optional<int> target) {
    json v = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", length}};
    if (target) v["target"] = *target;
    views.push_back(v);
    return static_cast<int>(views.size() - 1);
  };
  auto add_image = [&](const std::string& bytes, const std::string& mime) {
    const std::size_t off = bin.size();
    bin += bytes;
    images.push_back({{"bufferView", add_view(off, bytes.size(), std::nullopt)}, {"mimeType", mime}});
    pad4(bin, '\0');
    return static_cast<int>(images.size() - 1);
  };
  auto add_uvs = [&](std::vector<Vec2> uv) {
    for (Vec2& t : uv) t.y = 1.0f - t.y;  // glTF's UV origin is the top-left corner of the image
    const std::size_t off = bin.size();
    append_raw(bin, uv.data(), uv.size());
    accessors.push_back({{"bufferView", add_view(off, bin.size() - off, kArrayBuffer)}, {"componentType", kFloat}, {"count", uv.size()}, {"type", "VEC2"}});
    return accessors.size() - 1;
  };

  int texture = -1;
  if (!png.empty()) {
    // Linear minification with mipmaps (9987) and bilinear magnification (9729).
    samplers.push_back({{"magFilter", 9729}, {"minFilter", 9987}});
    textures.push_back({{"sampler", 0}, {"source", add_image(png, "image/png")}});
    texture = 0;
  }

  for (std::size_t mi = 0; mi < scene.meshes.size(); ++mi) {
    const Mesh& m = scene.meshes[mi];
    json attributes;
    // POSITION needs min/max (spec requirement).
    {
      const std::size_t off = bin.size();
      append_raw(bin, m.positions.data(), m.positions.size());
      const Bounds3 b = m.bounds();
      accessors.push_back({{"bufferView", add_view(off, bin.size() - off, kArrayBuffer)}, {"componentType", kFloat}, {"count", m.positions.size()},
                           {"type", "VEC3"}, {"min", {b.lo.x, b.lo.y, b.lo.z}}, {"max", {b.hi.x, b.hi.y, b.hi.z}}});
      attributes["POSITION"] = accessors.size() - 1;
    }
    if (!m.normals.empty()) {
      const std::size_t off = bin.size();
      append_raw(bin, m.normals.data(), m.normals.size());
      accessors.push_back({{"bufferView", add_view(off, bin.size() - off, kArrayBuffer)}, {"componentType", kFloat}, {"count", m.normals.size()}, {"type", "VEC3"}});
      attributes["NORMAL"] = accessors.size() - 1;
    }
    if (vertex_ao) {
      // COLOR_0 = (V, V, V), linear: glTF multiplies the base colour by it.
      std::vector<Vec3> colour(m.positions.size());
      for (std::size_t v = 0; v < colour.size(); ++v) {
        const float ao = (*vertex_ao)[first_vertex + v];
        colour[v] = {ao, ao, ao};
      }
      first_vertex += m.positions.size();
      const std::size_t off = bin.size();
      append_raw(bin, colour.data(), colour.size());
      accessors.push_back({{"bufferView", add_view(off, bin.size() - off, kArrayBuffer)}, {"componentType", kFloat}, {"count", colour.size()}, {"type", "VEC3"}});
      attributes["COLOR_0"] = accessors.size() - 1;
    }
    const bool has_uv = !m.uvs.empty();
    if (has_uv) attributes["TEXCOORD_0"] = add_uvs(m.uvs);
    const std::size_t off = bin.size();
    append_raw(bin, m.indices.data(), m.indices.size());
    accessors.push_back(
        {{"bufferView", add_view(off, bin.size() - off, kElementArrayBuffer)}, {"componentType", kUnsignedInt}, {"count", m.indices.size()}, {"type", "SCALAR"}});
    const std::size_t index_accessor = accessors.size() - 1;
    json material = fresh_material(m, mi);
    if (has_uv && texture >= 0) material["occlusionTexture"] = {{"index", texture}, {"texCoord", 0}, {"strength", 1.0}};
    materials.push_back(material);
    meshes.push_back({{"name", m.name}, {"primitives", {{{"attributes", attributes}, {"indices", index_accessor}, {"material", mi}, {"mode", 4}}}}});
    nodes.push_back({{"mesh", mi}, {"name", m.name}});
  }
  json root = {{"asset", {{"version", "2.0"}, {"generator", "ao bake"}}},
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
  write_file_atomically(path, [&](const std::filesystem::path& temp) {
    std::ofstream f(temp, std::ios::binary);
    f.write(out.data(), static_cast<std::streamsize>(out.size()));
    f.close();
    if (!f) throw SystemError(path.string() + ": cannot write");
  });
}

}  // namespace ao
