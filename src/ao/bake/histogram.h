// SPDX-License-Identifier: Apache-2.0
// Outside-in AO map baking: McGraw & Sowers, "Hardware Accelerated Per-Texel Ambient Occlusion
// Mapping" (ISVC 2008), on the CPU. See histogram.cpp and docs/methods/bake.md.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include <nlohmann/json.hpp>

#include "ao/core/params.h"

#include "ao/bake/bake_result.h"
#include "ao/bake/sphere_directions.h"
#include "ao/bake/texel_coverage.h"
#include "ao/core/progress.h"
#include "ao/scene/mesh.h"

namespace ao {

enum class BakeNormalization {
  Area,  ///< Exact: divide by each texel's world-space area (eq. 2), so V is absolute and matches the ray-traced baker.
  Max,   ///< The paper's: scale so that the largest texel value is 1 (assumes some texel is unoccluded).
};
std::string_view to_string(BakeNormalization n);
std::optional<BakeNormalization> parse_normalization(std::string_view name);

struct HistogramParams {
  int directions = 512;                                ///< D, directions on the whole sphere (about half light a texel). [1, 65536].
  DirectionSet direction_set = DirectionSet::Fibonacci; ///< Fibonacci (stratified; lower error) or the paper's Gaussian.
  float pixels_per_texel = 1.0f;   ///< View resolution: pixels along a texel's edge, for an average texel seen face-on. (0, 8].
  float point_size = 1.0f;         ///< Sec. 3.2 splat size in texels: 1 = one texel (no smoothing); > 1 blurs. [1, 16].
  BakeNormalization normalization = BakeNormalization::Area;  ///< See BakeNormalization.
  bool seam_fix = true;            ///< Sec. 3.3: refill chart-border texels less than half covered from the nearest well-covered texel.
  float min_samples = 16.0f;       ///< Texels expected to get fewer pixel samples than this (over all directions; slivers of charts) copy the nearest texel that gets enough. [0, 1e6]; 0 = off.
  bool bent_normals = false;       ///< Also accumulate the average unoccluded direction (sec. 3, last paragraph).
  std::uint32_t seed = 1;          ///< Keys the directions and the per-direction pixel-grid offsets.

  /// Throws InputError naming the bad field.
  void validate() const;
};
void to_json(nlohmann::json& j, const HistogramParams& p);
void from_json(const nlohmann::json& j, HistogramParams& p);
/// The histogram baker's parameter table (core/params.h).
const ParamTable<HistogramParams>& histogram_param_table();

/// Bakes V per texel of a W x H map (coverage.width x coverage.height) for the meshes of `scene`
/// that have UVs; meshes without UVs still occlude. `coverage` must come from
/// compute_texel_coverage(scene, W, H).
/// Distance is unlimited (eq. 1): a texel is open in a direction when no surface is in front of it.
/// Deterministic for a seed at any thread count (fixed-point accumulation, see the .cpp).
BakeResult bake_histogram(const Scene& scene, const TexelCoverage& coverage, const HistogramParams& params, const ProgressFn& progress = {});

/// World units per pixel of the per-direction views: the side of an average texel's patch of
/// surface divided by pixels_per_texel.
float histogram_pixel_size(const TexelCoverage& coverage, float pixels_per_texel);

}  // namespace ao
