// SPDX-License-Identifier: Apache-2.0
// UDIM tiles (udim.h).
#include "ao/bake/udim.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "ao/core/error.h"

namespace ao {

namespace {

constexpr const char* kToken = "<UDIM>";

// Position of a dot-separated "1001" in a file name ("ao.1001.png": 3), or npos.
std::size_t dotted_1001(const std::string& name) {
  for (std::size_t at = name.find("1001"); at != std::string::npos; at = name.find("1001", at + 1)) {
    const bool before = at > 0 && name[at - 1] == '.';
    const bool after = at + 4 < name.size() && name[at + 4] == '.';
    if (before && after) return at;
  }
  return std::string::npos;
}

}  // namespace

std::vector<UdimTile> udim_tiles(const Scene& scene) {
  std::set<int> numbers;
  for (const Mesh& m : scene.meshes) {
    if (m.uvs.empty()) continue;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      const std::uint32_t* i = &m.indices[3 * t];
      const double u = (static_cast<double>(m.uvs[i[0]].x) + m.uvs[i[1]].x + m.uvs[i[2]].x) / 3.0;
      const double v = (static_cast<double>(m.uvs[i[0]].y) + m.uvs[i[1]].y + m.uvs[i[2]].y) / 3.0;
      if (!(u >= 0 && u < 10 && v >= 0 && v < 100))
        throw InputError(scene.name + ": mesh '" + m.name + "' triangle " + std::to_string(t) + " has its UVs around (" + std::to_string(u) + ", " +
                         std::to_string(v) + "), outside the UDIM tiles (u in [0, 10), v in [0, 100))");
      numbers.insert(1001 + static_cast<int>(std::floor(u)) + 10 * static_cast<int>(std::floor(v)));
    }
  }
  std::vector<UdimTile> out;
  for (int n : numbers) out.push_back({(n - 1001) % 10, (n - 1001) / 10});
  return out;
}

Scene udim_tile_scene(const Scene& scene, const UdimTile& tile) {
  Scene s = scene;
  const Vec2 shift{static_cast<float>(tile.u), static_cast<float>(tile.v)};
  for (Mesh& m : s.meshes)
    for (Vec2& uv : m.uvs) uv = {uv.x - shift.x, uv.y - shift.y};
  return s;
}

bool is_udim_pattern(const std::filesystem::path& path) {
  const std::string name = path.filename().string();
  return name.find(kToken) != std::string::npos || dotted_1001(name) != std::string::npos;
}

std::filesystem::path udim_tile_path(const std::filesystem::path& pattern, int number) {
  std::string name = pattern.filename().string();
  const std::string n = std::to_string(number);
  if (const std::size_t at = name.find(kToken); at != std::string::npos) name.replace(at, std::string(kToken).size(), n);
  else if (const std::size_t d = dotted_1001(name); d != std::string::npos) name.replace(d, 4, n);
  return pattern.parent_path() / name;
}

}  // namespace ao
