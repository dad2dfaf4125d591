// SPDX-License-Identifier: Apache-2.0
// Texture-space denoising of a ray-traced AO map: a cross-bilateral filter (a Gaussian over each
// texel's neighbours in the map) guided by where the texels lie on the surface, so that it
// averages the Monte Carlo noise of texels that are neighbours on the surface and leaves alone
// texels that are only neighbours in the UV layout (another chart, the far side of a seam) or that
// lie across a crease. What lightmap bakers do for their AO (Unity's progressive lightmapper filters
// its AO in texture space); the measured trade of rays for filter width is in docs/methods/bake.md,
// "Denoising".
//
// A texel q near texel c gets the weight
//   w(q) = exp(-|uv_q - uv_c|^2 / (2 sigma^2))          the Gaussian, sigma in texels
//        * exp(-((p_q - p_c) . n_c / (tau h_c))^2 / 2)  off c's tangent plane (curvature, a crease, another layer)
//        * exp(-(G_q - G_c)^2 / (2 k^2 s^2))            values further apart than the noise explains (a contact shadow's edge)
//        * max(0, n_c . n_q)^8                          normals apart (a crease of 30 degrees: 0.32, 45: 0.06)
// and none when |p_q - p_c| > (2 |uv_q - uv_c| + 1.5) h_c: a UV neighbour that is far away on the
// surface is another chart or the other side of a seam. p and n are the texel's area-weighted patch
// centroid and mean normal (TexelGuides), h_c the world size of one texel at c (sqrt of world area
// over UV area) and tau = 1/2 texel.
//
// The value term runs in two passes. The first (the guide) filters the map at sigma_g = 1 texel with
// G = V, the texels' own values, and s^2 = var_c + var_q + 0.01^2 the variance of the difference of
// two texels' values, var the variance of each texel's mean as measured from its own samples
// (TexelGuides::variance: the spread of the samples within the strata of the texel's stratified
// sample set), k_g = 1.5; the floor keeps two texels whose samples all agreed (V = 0 or 1 everywhere
// in their strata) from refusing neighbours that differ by less than a 64-ray texel's typical noise.
// It also gives each guide value's variance, sum w^2 var / (sum w)^2 (the weighted mean's). The
// second filters the same raw values at the requested sigma, with G the guide and s^2 from the
// guide's variances, k = 2. A single texel's few samples measure its value and variance too roughly
// for the test: its variance, about V (1 - V) / n, is smaller the closer its value lies to 0 or 1,
// so where AO is near 1 a texel noisy upward takes fewer neighbours than one noisy downward and
// keeps more of its own value; the one-pass filter (k = 1.5 on the raw values) kept noise on
// smooth surfaces and lifted the map's mean. The guide's values are several times less noisy, so
// its test separates a contact shadow's edge from noise better, and k can be wider
// (docs/methods/bake.md, "Denoising", measures both).
//
// Each pass's value is not the weighted mean over the window (radius ceil(2 sigma)) but the value
// at c of a plane fitted to the window's values by weighted least squares, V ~ a + b_x dx + b_y dy with
// (dx, dy) the texel offsets, with a ridge lambda m0 on the slopes (m0 the sum of the weights,
// lambda = 1/2 texel^2):
//   minimise  sum_q w(q) (V_q - a - b_x dx_q - b_y dy_q)^2 + lambda m0 (b_x^2 + b_y^2),  V_c' = a
// (first-order regression, as local linear regression denoisers of Monte Carlo images do). Where
// the window's weights are symmetric about c it gives the weighted mean. Where they are not (a
// contact, whose neighbours on the floor lie on the side away from the box, or a chart's border)
// a mean takes the level of the side that weighs, and the fit follows the gradient through c
// instead: a linear ramp comes out unchanged. The ridge keeps the fit from extrapolating the
// noise of a lopsided window. Texels not valid neither take part nor change.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "ao/bake/texel_coverage.h"
#include "ao/core/image.h"
#include "ao/core/math.h"

namespace ao {

/// Largest filter sigma, texels: a wider filter is a lower-resolution map, which -s asks for directly.
inline constexpr float kMaxDenoiseSigma = 4.0f;

/// `ao bake`'s sigma for ray-traced maps: of 1, 1.5 and 2, the widest that keeps a box-on-floor
/// contact below unfiltered with a margin at 8-64 rays (9% at 64 rays; 2: 4%), 11-24% lower error
/// than 1 at 16-64 rays on the elephant, the decimated fandisk and high to low, within 1% of it on a
/// layout of small charts (docs/methods/bake.md, "Defaults"). The library's
/// RaytracedBakeParams::denoise stays 0: the library's estimate is the paper's integral.
inline constexpr float kDefaultBakeDenoise = 1.5f;

/// Where each covered texel lies on the surface, its patch's area-weighted centroid and unit mean
/// normal (world space), and how noisy its value is: the variance of its mean, measured from its
/// own samples (the bakers' StratifiedVariance). Held for the covered texels only, in row order
/// (slot k is the k-th covered texel): a map's charts cover 20-40% of it, and a dense layout made
/// the few-ray bakes fault in and zero 20 MB more of fresh memory at 1024^2. Slots start at
/// position 0, normal (0, 0, 1) and variance 0.
class TexelGuides {
 public:
  TexelGuides() = default;
  /// Guides for the texels set in `covered` (the map's TexelCoverage::mask), to be filled texel by texel.
  explicit TexelGuides(const Image<std::uint8_t>& covered);

  /// The slot of covered texel (x, y); `texel` = y * width + x.
  std::size_t slot(int x, int y) const {
    const std::size_t c = static_cast<std::size_t>(y) * chunks_ + static_cast<std::size_t>(x) / 64;
    const std::uint64_t below = (std::uint64_t{1} << (static_cast<unsigned>(x) % 64)) - 1;
    return chunk_first_[c] + static_cast<std::size_t>(std::popcount(chunk_bits_[c] & below));
  }
  std::size_t slot(std::size_t texel) const {
    const auto w = static_cast<std::size_t>(width_);
    return slot(static_cast<int>(texel % w), static_cast<int>(texel / w));
  }
  /// The slot of the first covered texel at or after the start of row y (the slots of a row's
  /// covered texels follow it in order).
  std::size_t row_slot(int y) const { return chunk_first_[static_cast<std::size_t>(y) * chunks_]; }

  std::vector<Vec3> position;
  std::vector<Vec3> normal;
  std::vector<float> variance;  ///< Variance of the texel's value (its mean), >= 0.

 private:
  int width_ = 0;
  std::size_t chunks_ = 0;                 // 64-texel chunks per row
  std::vector<std::uint64_t> chunk_bits_;  // per chunk: bit i set when its texel i is covered
  std::vector<std::uint32_t> chunk_first_; // per chunk: the slot of its first covered texel
};

/// Filters `visibility` (width x height of `cov`) in place over the texels set in `valid` (the
/// covered texels of `cov` that have a value) with the weights above, `guides` made for
/// `cov.mask`; `sigma` in (0, kMaxDenoiseSigma]. Deterministic at any thread count.
void denoise_map(Image<float>& visibility, const Image<std::uint8_t>& valid, const TexelCoverage& cov, const TexelGuides& guides, float sigma);

}  // namespace ao
