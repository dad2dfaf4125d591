// SPDX-License-Identifier: Apache-2.0
// The baked AO maps onto the materials of a glTF document (gltf_document_internal.h): glTF's
// occlusionTexture belongs to a material, which primitives of other meshes (or unbaked primitives)
// may share, so a shared material is cloned where its users need different maps.
#include <algorithm>
#include <set>
#include <utility>

#include "ao/io/gltf_document_internal.h"

namespace ao::io_detail {

void assign_occlusion_maps(tinygltf::Model& model, const std::map<int, int>& map_texture, int uv_set, std::vector<std::string>& warnings) {
  const std::string uv_attribute = "TEXCOORD_" + std::to_string(uv_set);
  const auto bakes = [&](const tinygltf::Primitive& p) { return gltf_is_triangles(p) && p.attributes.count("POSITION") && p.attributes.count(uv_attribute); };
  // What each material is asked to carry: the map of a mesh (>= 0) or no change (-1), per primitive.
  std::map<int, std::set<int>> uses;  // material -> the maps (or -1) its primitives need
  auto map_of = [&](int mesh, const tinygltf::Primitive& p) {
    const auto it = map_texture.find(mesh);
    return it != map_texture.end() && bakes(p) ? it->first : -1;
  };
  for (std::size_t m = 0; m < model.meshes.size(); ++m)
    for (const tinygltf::Primitive& p : model.meshes[m].primitives)
      if (p.material >= 0) uses[p.material].insert(map_of(static_cast<int>(m), p));
  std::map<std::pair<int, int>, int> material_for;  // (material or -1, map mesh) -> material index
  std::set<int> replaced;
  for (std::size_t m = 0; m < model.meshes.size(); ++m)
    for (tinygltf::Primitive& p : model.meshes[m].primitives) {
      const int map_mesh = map_of(static_cast<int>(m), p);
      if (map_mesh < 0) continue;
      const auto key = std::make_pair(p.material, map_mesh);
      auto it = material_for.find(key);
      if (it == material_for.end()) {
        int target = -1;
        if (p.material < 0) {
          // glTF's default material (white, metallic 1, roughness 1), named for the map.
          tinygltf::Material fresh;
          fresh.name = "ao " + gltf_plain_name(model, static_cast<int>(m));
          model.materials.push_back(fresh);
          target = static_cast<int>(model.materials.size() - 1);
        } else {
          const std::set<int>& u = uses[p.material];
          // In place when this map is its only use, or the first map of a material that every
          // user needs changed; otherwise a clone for this mesh's primitives.
          const bool first_taker = !u.count(-1) && std::none_of(material_for.begin(), material_for.end(), [&](const auto& e) { return e.first.first == p.material; });
          if (u.size() == 1 || first_taker) {
            target = p.material;
          } else {
            tinygltf::Material clone = model.materials[static_cast<std::size_t>(p.material)];
            // Appended piecewise: "literal" + std::string trips GCC 12's false -Wrestrict here.
            if (!clone.name.empty()) clone.name += ' ';
            clone.name += "(ao ";
            clone.name += gltf_plain_name(model, map_mesh);
            clone.name += ')';
            model.materials.push_back(std::move(clone));
            target = static_cast<int>(model.materials.size() - 1);
          }
          if (model.materials[static_cast<std::size_t>(target)].occlusionTexture.index >= 0) replaced.insert(p.material);
        }
        tinygltf::OcclusionTextureInfo& o = model.materials[static_cast<std::size_t>(target)].occlusionTexture;
        o = tinygltf::OcclusionTextureInfo();
        o.index = map_texture.at(map_mesh);
        o.texCoord = uv_set;
        o.strength = 1.0;
        it = material_for.emplace(key, target).first;
      }
      p.material = it->second;
    }
  for (int m : replaced) {
    const std::string& n = model.materials[static_cast<std::size_t>(m)].name;
    warnings.push_back("material " + (n.empty() ? std::to_string(m) : "'" + n + "'") + ": its occlusion texture is replaced by the baked map");
  }
}

}  // namespace ao::io_detail
