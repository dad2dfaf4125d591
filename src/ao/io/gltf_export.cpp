// GLB layout (glTF 2.0 spec, "Binary glTF Layout"): a 12-byte header (magic "glTF", version 2,
// total length), a JSON chunk padded with spaces to 4 bytes, and a BIN chunk padded with zeros.
// Every accessor's bufferView starts on a 4-byte boundary, as the spec requires for float/uint32.
// A glTF input's materials are read back through assimp (load_gltf_materials) and written with the
// baked map as their occlusionTexture; their images are copied into the BIN chunk.
#include "ao/io/gltf_export.h"

#include <assimp/GltfMaterial.h>
#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
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

// --- reading the source glTF's materials ------------------------------------------------------

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::optional<std::string> read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) return std::nullopt;
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return std::nullopt;
  return data;
}

/// "%20" -> " " in a relative URI.
std::string percent_decode(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) && std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
      out.push_back(static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16)));
      i += 2;
    } else {
      out.push_back(s[i]);
    }
  }
  return out;
}

/// The glTF core image types, by content.
std::string mime_of(const std::string& bytes) {
  if (bytes.size() >= 8 && bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0) return "image/png";
  if (bytes.size() >= 3 && static_cast<unsigned char>(bytes[0]) == 0xFF && static_cast<unsigned char>(bytes[1]) == 0xD8 &&
      static_cast<unsigned char>(bytes[2]) == 0xFF)
    return "image/jpeg";
  return {};
}

int gltf_wrap(int assimp_mode) {
  switch (assimp_mode) {
    case aiTextureMapMode_Clamp: return 33071;
    case aiTextureMapMode_Mirror: return 33648;
    default: return 10497;
  }
}

class SourceReader {
 public:
  SourceReader(const std::filesystem::path& path, const aiScene& ai, GltfSource& out) : path_(path), ai_(ai), out_(out) {}

  GltfMaterialInfo material(const aiMaterial& m) {
    GltfMaterialInfo info;
    aiString name;
    if (m.Get(AI_MATKEY_NAME, name) == aiReturn_SUCCESS) info.name = name.C_Str();
    aiColor4D c;
    if (m.Get(AI_MATKEY_BASE_COLOR, c) == aiReturn_SUCCESS || m.Get(AI_MATKEY_COLOR_DIFFUSE, c) == aiReturn_SUCCESS)
      info.base_color = {c.r, c.g, c.b, c.a};
    m.Get(AI_MATKEY_METALLIC_FACTOR, info.metallic);
    m.Get(AI_MATKEY_ROUGHNESS_FACTOR, info.roughness);
    aiColor3D e;
    if (m.Get(AI_MATKEY_COLOR_EMISSIVE, e) == aiReturn_SUCCESS) info.emissive = {e.r, e.g, e.b};
    m.Get(AI_MATKEY_EMISSIVE_INTENSITY, info.emissive_strength);
    aiString alpha;
    if (m.Get(AI_MATKEY_GLTF_ALPHAMODE, alpha) == aiReturn_SUCCESS && alpha.length > 0) info.alpha_mode = alpha.C_Str();
    if (info.alpha_mode != "OPAQUE" && info.alpha_mode != "MASK" && info.alpha_mode != "BLEND") info.alpha_mode = "OPAQUE";
    m.Get(AI_MATKEY_GLTF_ALPHACUTOFF, info.alpha_cutoff);
    int two_sided = 0;
    if (m.Get(AI_MATKEY_TWOSIDED, two_sided) == aiReturn_SUCCESS) info.double_sided = two_sided != 0;
    int shading = 0;  // assimp's glTF importer marks KHR_materials_unlit this way
    info.unlit = m.Get(AI_MATKEY_SHADING_MODEL, shading) == aiReturn_SUCCESS && shading == aiShadingMode_Unlit;
    info.base_color_texture = texture(m, aiTextureType_BASE_COLOR, "baseColorTexture");
    if (!info.base_color_texture) info.base_color_texture = texture(m, aiTextureType_DIFFUSE, "baseColorTexture");
    info.metallic_roughness_texture = texture(m, aiTextureType_UNKNOWN, "metallicRoughnessTexture");
    info.normal_texture = texture(m, aiTextureType_NORMALS, "normalTexture");
    info.emissive_texture = texture(m, aiTextureType_EMISSIVE, "emissiveTexture");
    return info;
  }

 private:
  void warn(const std::string& w) {
    for (const std::string& seen : out_.warnings)
      if (seen == w) return;
    out_.warnings.push_back(w);
  }

  std::optional<GltfTextureRef> texture(const aiMaterial& m, aiTextureType type, const std::string& what) {
    if (m.GetTextureCount(type) == 0) return std::nullopt;
    aiString tpath;
    if (m.GetTexture(type, 0, &tpath) != aiReturn_SUCCESS) return std::nullopt;
    const int image = image_index(tpath.C_Str(), what);
    if (image < 0) return std::nullopt;
    GltfTextureRef ref;
    ref.image = image;
    m.Get(AI_MATKEY_UVWSRC(type, 0), ref.uv_set);
    int mode = aiTextureMapMode_Wrap;
    if (m.Get(AI_MATKEY_MAPPINGMODE_U(type, 0), mode) == aiReturn_SUCCESS) ref.wrap_s = gltf_wrap(mode);
    mode = aiTextureMapMode_Wrap;
    if (m.Get(AI_MATKEY_MAPPINGMODE_V(type, 0), mode) == aiReturn_SUCCESS) ref.wrap_t = gltf_wrap(mode);
    m.Get(AI_MATKEY_GLTF_MAPPINGFILTER_MAG(type, 0), ref.mag_filter);
    m.Get(AI_MATKEY_GLTF_MAPPINGFILTER_MIN(type, 0), ref.min_filter);
    m.Get(AI_MATKEY_GLTF_TEXTURE_SCALE(type, 0), ref.scale);
    return ref;
  }

  /// Index into out_.images of the image at `key` (assimp's "*N" for embedded ones, else a URI
  /// relative to the file); -1 (with a warning) when it cannot be carried over.
  int image_index(const std::string& key, const std::string& what) {
    if (const auto it = cache_.find(key); it != cache_.end()) return it->second;
    int index = -1;
    std::string bytes;
    bool have = false;
    if (const aiTexture* t = ai_.GetEmbeddedTexture(key.c_str())) {
      if (t->mHeight != 0) {
        warn(what + " " + key + " dropped: assimp decoded it to raw texels");
      } else {
        bytes.assign(reinterpret_cast<const char*>(t->pcData), t->mWidth);
        have = true;
      }
    } else {
      const std::filesystem::path dir = path_.parent_path();
      std::optional<std::string> data = read_file(dir / key);
      if (!data) data = read_file(dir / percent_decode(key));
      if (data) {
        bytes = std::move(*data);
        have = true;
      } else {
        warn(what + " " + key + " dropped: the file cannot be read");
      }
    }
    if (have) {
      const std::string mime = mime_of(bytes);
      if (mime.empty()) {
        warn(what + " " + key + " dropped: not PNG or JPEG");
      } else {
        out_.images.push_back({std::move(bytes), mime});
        index = static_cast<int>(out_.images.size() - 1);
      }
    }
    cache_[key] = index;
    return index;
  }

  const std::filesystem::path& path_;
  const aiScene& ai_;
  GltfSource& out_;
  std::map<std::string, int> cache_;
};

}  // namespace

bool is_gltf_file(const std::filesystem::path& path) {
  const std::string ext = lower(path.extension().string());
  if (ext == ".gltf" || ext == ".glb") return true;
  std::ifstream in(path, std::ios::binary);
  char magic[4] = {};
  return in.read(magic, 4) && std::memcmp(magic, "glTF", 4) == 0;
}

GltfSource load_gltf_materials(const std::filesystem::path& path, const Scene& scene, int uv_set) {
  // The same import as load_scene_file (mesh_io.cpp), so the meshes come out in the same order
  // with the same vertices (JoinIdenticalVertices is deterministic).
  Assimp::Importer importer;
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* ai = nullptr;
  try {
    ai = importer.ReadFile(path.string(), aiProcess_ValidateDataStructure | aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                              aiProcess_PreTransformVertices | aiProcess_SortByPType);
  } catch (const std::exception& e) {
    throw InputError(path.string() + ": cannot read its materials (" + e.what() + ")");
  }
  if (ai == nullptr) throw InputError(path.string() + ": cannot read its materials (" + importer.GetErrorString() + ")");

  GltfSource out;
  out.materials.resize(scene.meshes.size());
  out.uv_sets.resize(scene.meshes.size());
  SourceReader reader(path, *ai, out);
  std::map<unsigned, GltfMaterialInfo> by_index;
  // assimp's glTF importer appends a default material (for primitives without one) after the
  // file's; such meshes keep the fresh material, as for other formats.
  const unsigned file_materials = ai->mNumMaterials > 0 ? ai->mNumMaterials - 1 : 0;
  std::size_t next = 0;
  for (unsigned m = 0; m < ai->mNumMeshes && next < scene.meshes.size(); ++m) {
    const aiMesh& in = *ai->mMeshes[m];
    if ((in.mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0) continue;
    const Mesh& mesh = scene.meshes[next];
    // validate_and_prepare drops meshes left without triangles: skip source meshes that do not match.
    if (mesh.name != in.mName.C_Str() || mesh.positions.size() != in.mNumVertices) continue;
    const std::size_t mi = next++;
    if (in.mMaterialIndex >= file_materials) continue;
    auto it = by_index.find(in.mMaterialIndex);
    if (it == by_index.end()) it = by_index.emplace(in.mMaterialIndex, reader.material(*ai->mMaterials[in.mMaterialIndex])).first;
    GltfMaterialInfo info = it->second;
    // Textures need their UV set on this mesh: the baked one is Mesh::uvs, others are copied.
    for (std::optional<GltfTextureRef>* t : {&info.base_color_texture, &info.metallic_roughness_texture, &info.normal_texture, &info.emissive_texture}) {
      if (!*t) continue;
      const int set = (*t)->uv_set;
      if (set == uv_set) {
        if (mesh.uvs.empty()) t->reset();
        continue;
      }
      if (out.uv_sets[mi].count(set)) continue;
      bool ok = set >= 0 && set < AI_MAX_NUMBER_OF_TEXTURECOORDS && in.HasTextureCoords(static_cast<unsigned>(set));
      std::vector<Vec2> uv;
      for (unsigned v = 0; ok && v < in.mNumVertices; ++v) {
        const aiVector3D c = in.mTextureCoords[set][v];
        ok = std::isfinite(c.x) && std::isfinite(c.y);
        uv.push_back({c.x, c.y});
      }
      if (ok) {
        out.uv_sets[mi][set] = std::move(uv);
      } else {
        out.warnings.push_back("mesh '" + mesh.name + "': a texture's UV set " + std::to_string(set) + " is missing or not finite, texture dropped");
        t->reset();
      }
    }
    out.materials[mi] = std::move(info);
  }
  if (next < scene.meshes.size())
    out.warnings.push_back(std::to_string(scene.meshes.size() - next) + " mesh(es) not matched to the file's, written with fresh materials");
  return out;
}

namespace {

// --- writing ----------------------------------------------------------------------------------

/// The shortest decimal that reads back as `f`, as a double (so 0.2f is written as 0.2, not 0.200000003).
double tidy(float f) {
  char buf[32];
  for (int digits = 6; digits <= 9; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, static_cast<double>(f));
    if (std::strtof(buf, nullptr) == f) break;
  }
  return std::strtod(buf, nullptr);
}
template <std::size_t N>
nlohmann::json tidy(const std::array<float, N>& a) {
  nlohmann::json out = nlohmann::json::array();
  for (float f : a) out.push_back(tidy(f));
  return out;
}

nlohmann::json fresh_material(const Mesh& m, std::size_t mi) {
  return {{"name", m.name.empty() ? "material" + std::to_string(mi) : m.name},
          {"pbrMetallicRoughness", {{"baseColorFactor", {m.albedo.x, m.albedo.y, m.albedo.z, 1.0}}, {"metallicFactor", 0.0}, {"roughnessFactor", 1.0}}}};
}

}  // namespace

void write_ao_glb(const std::filesystem::path& path, const Scene& scene, const std::string& png, const GltfSource* source,
                  const std::vector<float>* vertex_ao) {
  if (vertex_ao && vertex_ao->size() != scene.vertex_count())
    throw InputError(path.string() + ": per-vertex AO has " + std::to_string(vertex_ao->size()) + " values for " + std::to_string(scene.vertex_count()) + " vertices");
  std::size_t first_vertex = 0;  // of the current mesh in vertex_ao
  using nlohmann::json;
  std::string bin;
  json views = json::array(), accessors = json::array(), meshes = json::array(), materials = json::array(), nodes = json::array();
  json images = json::array(), samplers = json::array(), textures = json::array();
  std::set<std::string> extensions_used;
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
  std::vector<int> source_image;  // source image -> our image index
  if (source)
    for (const GltfImage& im : source->images) source_image.push_back(add_image(im.bytes, im.mime_type));
  // A texture (with its own sampler) for a source texture reference, mapped with TEXCOORD_`tex_coord`.
  auto texture_info = [&](const GltfTextureRef& ref, int tex_coord) {
    json sampler = {{"wrapS", ref.wrap_s}, {"wrapT", ref.wrap_t}};
    if (ref.mag_filter) sampler["magFilter"] = ref.mag_filter;
    if (ref.min_filter) sampler["minFilter"] = ref.min_filter;
    samplers.push_back(sampler);
    textures.push_back({{"sampler", samplers.size() - 1}, {"source", source_image.at(static_cast<std::size_t>(ref.image))}});
    return json{{"index", textures.size() - 1}, {"texCoord", tex_coord}};
  };

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
    // TEXCOORD_0 is the baked set; the source's other sets used by its textures follow (glTF wants
    // TEXCOORD_n numbered from 0 without gaps, so without a baked set the first of them is TEXCOORD_0).
    std::map<int, int> tex_coord_of_set;  // copied source UV set -> our TEXCOORD_n
    int next_tex_coord = 0;
    if (has_uv) attributes["TEXCOORD_" + std::to_string(next_tex_coord++)] = add_uvs(m.uvs);
    const GltfMaterialInfo* info = source && mi < source->materials.size() && source->materials[mi] ? &*source->materials[mi] : nullptr;
    if (info && mi < source->uv_sets.size())
      for (const auto& [set, uv] : source->uv_sets[mi]) {
        if (uv.size() != m.positions.size()) continue;
        tex_coord_of_set[set] = next_tex_coord;
        attributes["TEXCOORD_" + std::to_string(next_tex_coord++)] = add_uvs(uv);
      }
    const std::size_t off = bin.size();
    append_raw(bin, m.indices.data(), m.indices.size());
    accessors.push_back(
        {{"bufferView", add_view(off, bin.size() - off, kElementArrayBuffer)}, {"componentType", kUnsignedInt}, {"count", m.indices.size()}, {"type", "SCALAR"}});
    const std::size_t index_accessor = accessors.size() - 1;
    json material;
    if (!info) {
      material = fresh_material(m, mi);
    } else {
      // A source texture is kept when its UV set is written: the baked one (TEXCOORD_0) or a copied one.
      auto tex = [&](const std::optional<GltfTextureRef>& ref) -> std::optional<json> {
        if (!ref || ref->image < 0 || static_cast<std::size_t>(ref->image) >= source_image.size()) return std::nullopt;
        if (source->uv_sets.size() > mi && source->uv_sets[mi].count(ref->uv_set)) {
          const auto it = tex_coord_of_set.find(ref->uv_set);
          if (it == tex_coord_of_set.end()) return std::nullopt;
          return texture_info(*ref, it->second);
        }
        if (!has_uv) return std::nullopt;
        return texture_info(*ref, 0);
      };
      material["name"] = info->name.empty() ? (m.name.empty() ? "material" + std::to_string(mi) : m.name) : info->name;
      json pbr = {{"baseColorFactor", tidy(info->base_color)}, {"metallicFactor", tidy(info->metallic)}, {"roughnessFactor", tidy(info->roughness)}};
      if (auto t = tex(info->base_color_texture)) pbr["baseColorTexture"] = *t;
      if (auto t = tex(info->metallic_roughness_texture)) pbr["metallicRoughnessTexture"] = *t;
      material["pbrMetallicRoughness"] = pbr;
      if (auto t = tex(info->normal_texture)) {
        if (info->normal_texture->scale != 1.0f) (*t)["scale"] = tidy(info->normal_texture->scale);
        material["normalTexture"] = *t;
      }
      if (info->emissive != std::array<float, 3>{0, 0, 0}) material["emissiveFactor"] = tidy(info->emissive);
      if (auto t = tex(info->emissive_texture)) material["emissiveTexture"] = *t;
      if (info->alpha_mode != "OPAQUE") material["alphaMode"] = info->alpha_mode;
      if (info->alpha_mode == "MASK") material["alphaCutoff"] = tidy(info->alpha_cutoff);
      if (info->double_sided) material["doubleSided"] = true;
      if (info->unlit) {
        material["extensions"]["KHR_materials_unlit"] = json::object();
        extensions_used.insert("KHR_materials_unlit");
      }
      if (info->emissive_strength != 1.0f) {
        material["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", tidy(info->emissive_strength)}};
        extensions_used.insert("KHR_materials_emissive_strength");
      }
    }
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
  if (!extensions_used.empty()) root["extensionsUsed"] = extensions_used;
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
