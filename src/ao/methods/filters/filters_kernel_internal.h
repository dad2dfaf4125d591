// SPDX-License-Identifier: Apache-2.0
// Kernels of the two denoising filters, written once for every SIMD target (filters.cpp):
//  - the 4x4 depth-aware box filter of interleaved sampling (Keller and Heidrich 2001, as
//    volumetric AO and ambient transfer use it in their sec. 4.2; methods/interleave.h), and
//  - the separable cross-bilateral filter of Alchemy AO (McGuire et al. 2011, sec. 2;
//    methods/bilateral.h, which states its weights).
// The methods own the images, the parallel loops and the parameters; these kernels run one row at
// a time, pixels in the lanes of vectors, every tap's sums in registers.
#pragma once

#include <cstdint>

#include "ao/simd/aligned_internal.h"

namespace ao::simd {

/// The box filter's image: `channels` (1 to 4) sources and destinations of width * height pixels
/// of `stride` floats each (1: a plane; 3: an RGB image filtered as three interleaved channels),
/// the G-buffer's depth plane and object ids (0: uncovered).
struct BoxFilterImage {
  const float* const* src = nullptr;
  float* const* dst = nullptr;
  int channels = 1, stride = 1;
  const float* depth = nullptr;
  const std::uint32_t* object_id = nullptr;
  int width = 0, height = 0;
};

/// Rows [y0, y1) of the filter: each covered pixel gets the mean of its window of 4 x 4 pixels
/// (offsets -2..+1 in x and y, so the window holds each of the 16 pattern positions once) over the
/// covered neighbours whose depth differs from its own by at most `depth_limit`; uncovered pixels
/// (and a pixel with no such neighbour) keep their value. Taps are summed in the same order (dy,
/// then dx) for every channel count, layout and target, and a skipped tap adds +0 exactly as a
/// missing one: the results do not depend on either.
void box_filter_rows(const BoxFilterImage& image, float depth_limit, int y0, int y1);

/// The bilateral filter's centre pixels of one row segment, folded into three coefficients per
/// pass (methods/bilateral.cpp derives them): the tangent-plane distance of a tap at depth d on the
/// ray coordinate t, over the scale and halved, is |d (a t + b) - c|; cov = 1 on covered pixels.
struct BilateralCentres {
  AlignedVector<float> a, b, c, cov;  ///< padded(count) entries each.
};

/// The centres of the `count` pixels at x0.. of row y: normals (`normal`, xyz triples) and depths
/// of the row, camera ray x coordinates rx(x) = ray_ax (x + 1/2) + ray_bx and y coordinate `ry`
/// (the row's); `vertical`: the pass along y (the tap coordinate t is the ray's y), else along x.
void bilateral_centres(BilateralCentres& centres, const float* normal, const float* depth, const std::uint32_t* object_id, int x0, int count,
                       float ray_ax, float ray_bx, float ry, float plane_sigma, bool vertical);

/// One 1-D pass over `count` pixels: out[k] = sum_j w_j v_j / sum_j w_j with
/// w_j = spatial[j] max(0, 1 - (d (a t + b) - c)^2)^2 on covered pixels, in[k] elsewhere. Tap j
/// reads depths td[j][k] and values tv[j][k]; its ray coordinate is tt[j][k] (`per_pixel_t`) or
/// tt[j][0] for the whole row. Background taps (depth +infinity) get weight 0. Taps are summed in
/// order, the same on every target.
void bilateral_taps(const BilateralCentres& centres, int count, int taps, const float* spatial, const float* const* tt, bool per_pixel_t,
                    const float* const* td, const float* const* tv, const float* in, float* out);

}  // namespace ao::simd
