// SPDX-License-Identifier: Apache-2.0
// Bake groups (see bake_groups.h). Merging is exact for the area-weighted texel mean of eq. 2 of
// the per-texel AO paper: a texel shared by two groups' charts averages their V by the world area
// each covers in it.
#include "ao/bake/bake_groups.h"

#include <algorithm>
#include <cctype>
#include <map>
#include <optional>
#include <set>

#include "ao/core/error.h"
#include "ao/scene/procedural.h"

namespace ao {

namespace {

bool ends_with_ci(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  for (std::size_t i = 0; i < suffix.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(s[s.size() - suffix.size() + i])) != suffix[i]) return false;
  return true;
}

bool has_uvs(const Scene& s) {
  return std::any_of(s.meshes.begin(), s.meshes.end(), [](const Mesh& m) { return !m.uvs.empty(); });
}

}  // namespace

std::string bake_group_key(const std::string& name) {
  for (const std::string suffix : {"_low", "_high"})
    if (ends_with_ci(name, suffix)) return name.substr(0, name.size() - suffix.size());
  return name;
}

std::vector<BakeGroup> groups_by_name(const Scene& low, const Scene& high, std::vector<std::string>* unused_high) {
  std::map<std::string, BakeGroup> by_key;
  std::vector<std::string> order;
  for (std::size_t i = 0; i < low.meshes.size(); ++i) {
    const std::string key = bake_group_key(low.meshes[i].name);
    auto [it, inserted] = by_key.try_emplace(key, BakeGroup{key, {}, {}});
    if (inserted) order.push_back(key);
    it->second.meshes.push_back(i);
  }
  for (std::size_t i = 0; i < high.meshes.size(); ++i) {
    const auto it = by_key.find(bake_group_key(high.meshes[i].name));
    if (it != by_key.end()) it->second.high.push_back(i);
    else if (unused_high) unused_high->push_back(high.meshes[i].name);
  }
  std::vector<BakeGroup> out;
  for (const std::string& key : order) {
    BakeGroup& g = by_key[key];
    if (g.high.empty())
      throw InputError(low.name + ": mesh '" + low.meshes[g.meshes.front()].name + "' has no high mesh named '" + key +
                       "_high' (or '" + key + "') to bake from (--match-by-name)");
    out.push_back(std::move(g));
  }
  return out;
}

std::vector<BakeGroup> groups_from_lists(const Scene& scene, const std::vector<std::vector<std::string>>& lists) {
  std::map<std::string, std::vector<std::size_t>> by_name;
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) by_name[scene.meshes[i].name].push_back(i);
  std::vector<BakeGroup> out;
  std::set<std::size_t> used;
  for (const auto& list : lists) {
    BakeGroup g;
    for (const std::string& name : list) {
      const auto it = by_name.find(name);
      if (it == by_name.end()) throw InputError("--group: " + scene.name + " has no mesh named '" + name + "'");
      for (std::size_t i : it->second) {
        if (!used.insert(i).second) throw InputError("--group: mesh '" + name + "' is in two groups");
        g.meshes.push_back(i);
      }
      g.name += (g.name.empty() ? "" : ",") + name;
    }
    std::sort(g.meshes.begin(), g.meshes.end());
    out.push_back(std::move(g));
  }
  BakeGroup rest{"(other meshes)", {}, {}};
  for (std::size_t i = 0; i < scene.meshes.size(); ++i)
    if (!used.count(i)) rest.meshes.push_back(i);
  if (!rest.meshes.empty()) out.push_back(std::move(rest));
  return out;
}

std::vector<BakeGroup> groups_per_mesh(const Scene& scene) {
  std::vector<BakeGroup> out;
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) out.push_back({scene.meshes[i].name, {i}, {}});
  return out;
}

Mesh make_floor_occluder(const Bounds3& b) {
  const float d = b.diagonal(), cx = 0.5f * (b.lo.x + b.hi.x), cz = 0.5f * (b.lo.z + b.hi.z);
  // A closed slab (5 % of a diagonal thick) rather than one quad, so it occludes from either side
  // in both bakers (the histogram baker culls back faces).
  Mesh floor = make_box({cx - 10 * d, b.lo.y - 0.05f * d, cz - 10 * d}, {cx + 10 * d, b.lo.y, cz + 10 * d});
  floor.name = "floor";
  return floor;
}

namespace {

// Whether `group` holds every mesh of `scene`, in order: its group scene's UV meshes are then
// scene's, at the same indices.
bool is_every_mesh(const BakeGroup& group, const Scene& scene) {
  if (group.meshes.size() != scene.meshes.size()) return false;
  for (std::size_t i = 0; i < group.meshes.size(); ++i)
    if (group.meshes[i] != i) return false;
  return true;
}

}  // namespace

Scene group_scene(const Scene& scene, const BakeGroup& group, const std::vector<Mesh>& occluders) {
  Scene s;
  s.name = scene.name;
  for (std::size_t i : group.meshes) s.meshes.push_back(scene.meshes[i]);
  for (const Mesh& m : occluders) {
    s.meshes.push_back(m);
    s.meshes.back().uvs.clear();
  }
  return s;
}

BakeResult bake_groups(const Scene& scene, const std::vector<BakeGroup>& groups, const std::vector<Mesh>& occluders, int width, int height,
                       const std::function<BakeResult(const Scene&, const TexelCoverage&, const BakeGroup&)>& bake,
                       const TexelCoverage* scene_coverage) {
  BakeResult out;
  Image<double> weighted(width, height, 0.0), area(width, height, 0.0);
  Image<Vec3> bent;
  bool any = false;
  for (const BakeGroup& g : groups) {
    const Scene gs = group_scene(scene, g, occluders);
    if (!has_uvs(gs)) continue;
    const bool whole_scene = scene_coverage && scene_coverage->width == width && scene_coverage->height == height && is_every_mesh(g, scene);
    std::optional<TexelCoverage> own;
    if (!whole_scene) own = compute_texel_coverage(gs, width, height);
    const TexelCoverage& cov = whole_scene ? *scene_coverage : *own;
    BakeResult r = bake(gs, cov, g);
    if (!any) {
      out.visibility = Image<float>(width, height, 0.0f);
      out.mask = Image<std::uint8_t>(width, height, std::uint8_t{0});
      if (!r.missed.empty()) out.missed = Image<std::uint8_t>(width, height, std::uint8_t{0});
      if (!r.bent_normal.empty()) out.bent_normal = Image<Vec3>(width, height, Vec3{0, 0, 0});
      any = true;
    }
    for (std::size_t i = 0; i < cov.mask.size(); ++i) {
      if (!cov.mask[i]) continue;
      weighted[i] += static_cast<double>(r.visibility[i]) * cov.world_area[i];
      area[i] += cov.world_area[i];
      out.mask[i] = 1;
      if (!out.missed.empty() && !r.missed.empty() && r.missed[i]) out.missed[i] = 1;
      if (!out.bent_normal.empty() && !r.bent_normal.empty()) out.bent_normal[i] += r.bent_normal[i] * cov.world_area[i];
    }
    out.rays += r.rays;
    out.fragments += r.fragments;
    out.directions = r.directions;
    for (std::string& w : r.warnings) out.warnings.push_back(g.name.empty() ? w : "group " + g.name + ": " + w);
    out.stats["groups"].push_back({{"group", g.name}, {"meshes", g.meshes.size()}, {"texels", cov.covered_texels}, {"stats", r.stats}});
  }
  if (!any) throw InputError(scene.name + ": no bake group has a mesh with UV coordinates");
  for (std::size_t i = 0; i < out.visibility.size(); ++i) {
    if (!out.mask[i]) continue;
    ++out.covered_texels;
    out.visibility[i] = static_cast<float>(weighted[i] / std::max(area[i], 1e-300));
    if (!out.bent_normal.empty()) out.bent_normal[i] = length(out.bent_normal[i]) > 0 ? normalize(out.bent_normal[i]) : out.bent_normal[i];
    if (!out.missed.empty()) out.missed_texels += out.missed[i];
  }
  return out;
}

}  // namespace ao
