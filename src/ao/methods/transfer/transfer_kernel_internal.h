// SPDX-License-Identifier: Apache-2.0
// Ambient transfer's kernels (transfer_kernel.cpp), compiled once per SIMD target; transfer.cpp
// derives its samples and inputs from the paper and hands them over.
#pragma once

#include <cstddef>
#include <cstdint>

#include "ao/core/math.h"
#include "ao/methods/screen_space_kernel_internal.h"

namespace ao::simd {

/// Ambient transfer (AT eq. 6, 9) on the depth buffer. Its inputs besides the tests of
/// count_open_rays: the reflectance a blocked ray brings back (a~ of eq. 9), either from a palette
/// of at most 32 RGB values whose index sits in the low 5 bits of each pixel's packed depth word, or
/// read at the occluder's pixel of an RGB image; in the radiance mode also the occluder's direct
/// radiance Ld~ (never with a palette).
struct TransferInputs {
  const std::uint32_t* packed = nullptr;  ///< Depth words with a palette index in the low 5 bits; null: no palette.
  const float* palette = nullptr;         ///< 96 floats: the palette's R, G, B planes of 32 entries.
  const float* albedo = nullptr;          ///< RGB triples per pixel: a~ without a palette.
  const float* direct = nullptr;          ///< RGB triples per pixel: Ld~ (radiance mode), else null.
  float albedo_scale = 1;                 ///< Multiplies a~ and Ld~.
};

/// Where ambient transfer's results go, per pixel of the G-buffer (index y * width + x).
struct TransferOutputs {
  float* r = nullptr;  ///< W's R, or (with `rgb`) its Rec. 709 luminance.
  float* g = nullptr;  ///< W's G (unused with `rgb`).
  float* b = nullptr;  ///< W's B (unused with `rgb`).
  float* o = nullptr;  ///< O = sum I / n (eq. 5 from the same tests).
  Vec3* rgb = nullptr; ///< W interleaved, or null.
};

/// AT sec. 4 and eq. 9 for the entries of `row` (pixel offset of entry k from `out`'s row start
/// `row_base`: row.index[k]): per ray, the nearest of its m test points x + (j/m) w r that is
/// occluded (as count_open_rays) names the occluder pixel whose a~ (and Ld~) the ray brings back;
/// W = sum I / (n - scale sum (1 - I) a~) clamped to 1 (0 when no ray is open), or in the radiance
/// mode (sum I + scale sum (1 - I) Ld~) / (n - scale sum (1 - I) a~) (0 unless both are > 0).
void transfer_rays(const CoveredPixels& row, const DepthPlane& plane, const TestPoints& samples, int m, float far_limit,
                   const TransferInputs& in, std::size_t row_base, const TransferOutputs& out);

/// Transfer's last pass over filtered planes: rgb[k] = (r[k], g[k], b[k]) (W interleaved) and lum[k]
/// its Rec. 709 luminance for k < n. `lum` may be `r` (each value is read before it is written).
void interleave_transfer(const float* r, const float* g, const float* b, std::size_t n, Vec3* rgb, float* lum);

}  // namespace ao::simd
