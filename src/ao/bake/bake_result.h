// SPDX-License-Identifier: Apache-2.0
// What a texel baker returns, whichever method made it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/image.h"
#include "ao/core/math.h"

namespace ao {

struct BakeResult {
  Image<float> visibility;       ///< N x N, V in [0,1] on covered texels; 0 elsewhere until padded.
  Image<std::uint8_t> mask;      ///< 1 on texels that cover surface (before padding).
  Image<Vec3> bent_normal;       ///< Unit average unoccluded direction (world space) per texel; empty unless asked.
  Image<std::uint8_t> missed;    ///< High-to-low: 1 on covered texels whose every cage ray missed the high mesh; empty otherwise.
  std::size_t covered_texels = 0;
  std::size_t missed_texels = 0; ///< High-to-low: texels set in `missed`.
  std::uint64_t rays = 0;        ///< Ray-traced baker: rays traced.
  int directions = 0;            ///< Histogram baker: directions rendered.
  std::uint64_t fragments = 0;   ///< Histogram baker: visible pixels scattered, over all directions.
  std::vector<std::string> warnings;  ///< From the UV layout (overlaps, degenerate UVs, ...).
  nlohmann::json stats;          ///< Method-specific numbers (view size, timings of stages, ...).
};

}  // namespace ao
