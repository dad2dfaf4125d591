// SPDX-License-Identifier: Apache-2.0
// UDIM tiles: a UV layout spread over unit squares, tile (k, r) holding u in [k, k+1) and
// v in [r, r+1) and numbered 1001 + k + 10 r (k in [0, 9], r in [0, 99]), the convention of Mari,
// Substance, Blender and USD. Each tile is baked as a map of its own.
#pragma once

#include <filesystem>
#include <optional>
#include <vector>

#include "ao/scene/mesh.h"

namespace ao {

struct UdimTile {
  int u = 0, v = 0;  ///< k and r: the tile covers u in [k, k+1), v in [r, r+1).
  int number() const { return 1001 + u + 10 * v; }
};

/// The tiles holding the UV centroid of at least one triangle (of the meshes with UVs), sorted by
/// number. InputError naming the mesh when a centroid lies outside the UDIM range (u in [0, 10),
/// v in [0, 100)) or is not finite.
std::vector<UdimTile> udim_tiles(const Scene& scene);

/// The scene with every UV shifted by (-k, -r), so tile (k, r) is the unit square a map covers;
/// triangles of other tiles fall outside it and only occlude.
Scene udim_tile_scene(const Scene& scene, const UdimTile& tile);

/// True when an output name asks for UDIM tiles: it contains the token `<UDIM>` or the number
/// 1001 as a whole dot-separated part of the file name (`ao.1001.png`, `ao_1001.png` does not count).
bool is_udim_pattern(const std::filesystem::path& path);

/// The file of one tile: `<UDIM>` (or the dot-separated 1001) replaced by the tile's number.
std::filesystem::path udim_tile_path(const std::filesystem::path& pattern, int number);

}  // namespace ao
