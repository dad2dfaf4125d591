// SPDX-License-Identifier: Apache-2.0
// The bake filter's inner loop (denoise.h), lane-parallel over the texels of a row: denoise.cpp
// lays out a band of the map's rows as planes (one float per texel per quantity, the band's rows
// and r texels of border on every side), and denoise_kernel.cpp, compiled once per SIMD target,
// filters a row of it, for either of the filter's two passes. Internal to src/ao/bake.
#pragma once

#include <cstddef>

namespace ao::detail {

/// A band of rows of the filter's inputs. Texel (x, y) of the band (y from -radius to rows - 1 +
/// radius, x from -radius to stride - radius - 1) is element (y + radius) * stride + x + radius of
/// each plane. A texel that takes no part (not valid, outside the map, the border) has a NaN
/// position x, which fails every distance test, and its other planes 0; a texel whose own value
/// is filtered has area > 0. stride leaves room for a whole vector of lanes of the widest target
/// past the last texel of a row, radius texels to either side.
struct DenoiseBand {
  const float *px, *py, *pz;  ///< Patch centroid, world space.
  const float *nx, *ny, *nz;  ///< Unit mean normal.
  const float *value, *variance;  ///< What is filtered: the raw map, and the variance of each texel's value.
  /// What the value term compares, and its variance: the raw map again (the first pass), or the
  /// first pass's result (the second).
  const float *guide, *guide_variance;
  const float* area;  ///< h^2, the world area of one texel at the texel; 0 for one not filtered.
  std::ptrdiff_t stride = 0;
  int width = 0;   ///< Texels of a row of the map.
  int radius = 0;  ///< r, texels.
  /// Per tap of the (2r + 1)^2 window, row by row: the Gaussian and the squared chart gate, (2 |d| + 1.5)^2.
  const float *gauss, *gate;
  float plane_tolerance2 = 0;  ///< tau^2, texels^2.
  float range_scale = 0;       ///< 1 / k^2.
  float variance_floor = 0;
  float slope_ridge = 0;       ///< lambda, texels^2.
};

/// Filters row `row` (0 <= row < the band's rows) of `band` into out[0, width): every texel with
/// area > 0 gets the plane fit's value at it, clamped to [0, 1] (denoise.h); the others are not
/// written. Run under FlushDenormalsScope: weights underflow.
/// With out_variance, also the variance of each written value, sum w^2 var / (sum w)^2 (the weighted mean's).
void denoise_row(const DenoiseBand& band, int row, float* out, float* out_variance);

}  // namespace ao::detail
