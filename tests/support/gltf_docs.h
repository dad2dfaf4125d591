// SPDX-License-Identifier: Apache-2.0
// glTF documents for the round-trip tests of `ao bake` (built here as GLB, nothing read from disk),
// and a reader of the GLB container (glTF 2.0 spec, "Binary glTF Layout").
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace ao::test {

struct GlbFile {
  nlohmann::json json;
  std::string bin;
};

inline std::uint32_t glb_u32(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, s.data() + at, 4);
  return v;
}

inline GlbFile parse_glb_file(const std::string& f) {
  if (f.size() < 20 || f.compare(0, 4, "glTF") != 0) throw std::runtime_error("not a GLB");
  const std::uint32_t json_length = glb_u32(f, 12);
  if (20 + static_cast<std::size_t>(json_length) > f.size()) throw std::runtime_error("JSON chunk overruns the file");
  GlbFile g;
  g.json = nlohmann::json::parse(f.substr(20, json_length));
  const std::size_t bin_at = 20 + json_length;
  if (bin_at + 8 <= f.size()) {
    const std::uint32_t bin_length = glb_u32(f, bin_at);
    if (bin_at + 8 + bin_length > f.size()) throw std::runtime_error("BIN chunk overruns the file");
    g.bin = f.substr(bin_at + 8, bin_length);
  }
  return g;
}

/// The bytes of bufferView `view` of a GLB's binary chunk.
inline std::string glb_view(const GlbFile& g, int view) {
  const nlohmann::json& v = g.json["bufferViews"][static_cast<std::size_t>(view)];
  return g.bin.substr(v.value("byteOffset", std::size_t{0}), v["byteLength"].get<std::size_t>());
}

/// Accessor `index` of a GLB as floats (float components, tightly packed).
inline std::vector<float> glb_floats(const GlbFile& g, int index) {
  const nlohmann::json& a = g.json["accessors"][static_cast<std::size_t>(index)];
  const std::string bytes = glb_view(g, a["bufferView"].get<int>());
  const std::size_t comps = a["type"] == "VEC3" ? 3 : a["type"] == "VEC2" ? 2 : 1;
  std::vector<float> out(a["count"].get<std::size_t>() * comps);
  std::memcpy(out.data(), bytes.data() + a.value("byteOffset", std::size_t{0}), out.size() * 4);
  return out;
}

/// Builds GLB bytes from a document and its binary chunk (padded here).
inline std::string make_glb(nlohmann::json doc, std::string bin) {
  while (bin.size() % 4) bin.push_back('\0');
  doc["buffers"] = {{{"byteLength", bin.size()}}};
  std::string js = doc.dump();
  while (js.size() % 4) js.push_back(' ');
  std::string out;
  auto put = [&](std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  out += "glTF";
  put(2);
  put(static_cast<std::uint32_t>(12 + 8 + js.size() + 8 + bin.size()));
  put(static_cast<std::uint32_t>(js.size()));
  put(0x4E4F534Au);  // JSON
  out += js;
  put(static_cast<std::uint32_t>(bin.size()));
  put(0x004E4942u);  // BIN
  out += bin;
  return out;
}

/// Appends accessor data to a document under construction; returns the accessor index.
class GltfBuilder {
 public:
  nlohmann::json doc = {{"asset", {{"version", "2.0"}}}, {"bufferViews", nlohmann::json::array()}, {"accessors", nlohmann::json::array()}};
  std::string bin;

  int floats(const std::vector<float>& v, const char* type, bool with_bounds = false) {
    const std::size_t comps = std::string(type) == "VEC3" ? 3 : 2;
    nlohmann::json a = {{"bufferView", view(v.data(), v.size() * 4, 34962)}, {"componentType", 5126}, {"count", v.size() / comps}, {"type", type}};
    if (with_bounds) {
      std::vector<float> lo(comps, 1e30f), hi(comps, -1e30f);
      for (std::size_t i = 0; i < v.size(); ++i) lo[i % comps] = std::min(lo[i % comps], v[i]), hi[i % comps] = std::max(hi[i % comps], v[i]);
      a["min"] = lo, a["max"] = hi;
    }
    doc["accessors"].push_back(a);
    return static_cast<int>(doc["accessors"].size() - 1);
  }
  int indices(const std::vector<std::uint32_t>& v) {
    doc["accessors"].push_back({{"bufferView", view(v.data(), v.size() * 4, 34963)}, {"componentType", 5125}, {"count", v.size()}, {"type", "SCALAR"}});
    return static_cast<int>(doc["accessors"].size() - 1);
  }
  /// A primitive of an axis-aligned box [lo, hi]^3 with flat normals; with `uvs`, face f gets
  /// the cell (f % 3, f / 3) of a 3 x 2 grid of the UV square (glTF's v down), inset by 0.02.
  /// Faces in the order -x, +x, -y, +y, -z, +z.
  nlohmann::json box(const float lo[3], const float hi[3], bool uvs, int material) {
    std::vector<float> pos, nor, uv;
    std::vector<std::uint32_t> idx;
    for (int f = 0; f < 6; ++f) {
      const int axis = f / 2, u_axis = (axis + 1) % 3, v_axis = (axis + 2) % 3;
      const bool plus = f % 2;
      // Corners counter-clockwise seen from outside.
      const float su[4] = {0, 1, 1, 0}, sv[4] = {0, 0, 1, 1};
      for (int k = 0; k < 4; ++k) {
        float p[3];
        p[axis] = plus ? hi[axis] : lo[axis];
        const float a = plus ? su[k] : sv[k], b = plus ? sv[k] : su[k];
        p[u_axis] = a ? hi[u_axis] : lo[u_axis];
        p[v_axis] = b ? hi[v_axis] : lo[v_axis];
        pos.insert(pos.end(), p, p + 3);
        float n[3] = {0, 0, 0};
        n[axis] = plus ? 1.0f : -1.0f;
        nor.insert(nor.end(), n, n + 3);
        const float u0 = (f % 3) / 3.0f + 0.02f, u1 = (f % 3 + 1) / 3.0f - 0.02f, v0 = (f / 3) / 2.0f + 0.02f, v1 = (f / 3 + 1) / 2.0f - 0.02f;
        uv.push_back(a ? u1 : u0);
        uv.push_back(b ? v1 : v0);
      }
      const std::uint32_t b = static_cast<std::uint32_t>(4 * f);
      idx.insert(idx.end(), {b, b + 1, b + 2, b, b + 2, b + 3});
    }
    nlohmann::json attributes = {{"POSITION", floats(pos, "VEC3", true)}, {"NORMAL", floats(nor, "VEC3")}};
    if (uvs) attributes["TEXCOORD_0"] = floats(uv, "VEC2");
    nlohmann::json prim = {{"attributes", attributes}, {"indices", indices(idx)}};
    if (material >= 0) prim["material"] = material;
    return prim;
  }
  std::string glb() const { return make_glb(doc, bin); }

 private:
  int view(const void* data, std::size_t bytes, int target) {
    while (bin.size() % 4) bin.push_back('\0');
    doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes}, {"target", target}});
    bin.append(static_cast<const char*>(data), bytes);
    return static_cast<int>(doc["bufferViews"].size() - 1);
  }
};

/// Two unit cubes side by side, 0.2 apart along x, both instances of one mesh "Cube" (UVs: a 3 x 2
/// grid of face cells, GltfBuilder::box) with the material "Red": nodes "Root" (no mesh, lifted by
/// 1 in y) with children "Left" (x = -0.6) and "Right" (x = +0.6). The first instance is Left, whose
/// +x face looks at Right from 0.2 away and whose -x face sees nothing.
inline std::string instanced_cubes_glb() {
  GltfBuilder b;
  const float lo[3] = {-0.5f, -0.5f, -0.5f}, hi[3] = {0.5f, 0.5f, 0.5f};
  b.doc["meshes"] = {{{"name", "Cube"}, {"primitives", {b.box(lo, hi, true, 0)}}}};
  b.doc["materials"] = {{{"name", "Red"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.1, 0.1, 1.0}}, {"metallicFactor", 0.0}}}}};
  b.doc["nodes"] = {{{"name", "Root"}, {"children", {1, 2}}, {"translation", {0.0, 1.0, 0.0}}},
                    {{"name", "Left"}, {"mesh", 0}, {"translation", {-0.6, 0.0, 0.0}}},
                    {{"name", "Right"}, {"mesh", 0}, {"translation", {0.6, 0.0, 0.0}}}};
  b.doc["scenes"] = {{{"name", "Scene"}, {"nodes", {0}}}};
  b.doc["scene"] = 0;
  return b.glb();
}

/// One material "Shared" used by three meshes: "Cube" (UVs), "Plate" (a flat box under it, UVs)
/// and "Post" (no UVs), each instanced once. Baking gives Cube and Plate a map each, so each
/// needs its own copy of the material, and Post keeps the original.
inline std::string shared_material_glb() {
  GltfBuilder b;
  const float clo[3] = {-0.5f, 0.0f, -0.5f}, chi[3] = {0.5f, 1.0f, 0.5f};
  const float plo[3] = {-2.0f, -0.1f, -2.0f}, phi[3] = {2.0f, 0.0f, 2.0f};
  const float slo[3] = {1.0f, 0.0f, 1.0f}, shi[3] = {1.2f, 2.0f, 1.2f};
  b.doc["meshes"] = {{{"name", "Cube"}, {"primitives", {b.box(clo, chi, true, 0)}}},
                     {{"name", "Plate"}, {"primitives", {b.box(plo, phi, true, 0)}}},
                     {{"name", "Post"}, {"primitives", {b.box(slo, shi, false, 0)}}}};
  b.doc["materials"] = {{{"name", "Shared"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.2, 0.5, 0.9, 1.0}}}}, {"doubleSided", true}}};
  b.doc["nodes"] = {{{"name", "CubeNode"}, {"mesh", 0}}, {{"name", "PlateNode"}, {"mesh", 1}}, {{"name", "PostNode"}, {"mesh", 2}}};
  b.doc["scenes"] = {{{"nodes", {0, 1, 2}}}};
  b.doc["scene"] = 0;
  return b.glb();
}

}  // namespace ao::test
