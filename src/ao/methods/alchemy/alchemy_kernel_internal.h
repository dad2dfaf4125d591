// SPDX-License-Identifier: Apache-2.0
// Kernel of Alchemy AO's estimator (McGuire, Osman, Bukowski, Hennessy, "The Alchemy Screen-Space
// Ambient Obscurance Algorithm", HPG 2011, eq. 10), written once for every SIMD target
// (alchemy.cpp). methods/alchemy.cpp turns the paper's constants into world units and builds the
// sample pattern; this kernel runs it for a row of pixels in the lanes of vectors.
#pragma once

#include <cstdint>

#include "ao/methods/alchemy/alchemy_shared.h"
#include "ao/simd/depth_internal.h"

namespace ao::simd {

/// What the estimator reads: the G-buffer's depth plane, normals and ids (DepthView), its constants
/// and the sample pattern.
struct AlchemyInputs : DepthView {
  float radius = 1;       ///< r of eq. 9-10, world units.
  float max_pixel_radius = shared::kAlchemyMaxPixelRadius;  ///< Cap on the disk's screen radius, pixels.
  float epsilon = 0;      ///< epsilon of eq. 10, world units squared.
  float beta = 0;         ///< beta of eq. 10 (multiplies z_C).
  float scale = 0;        ///< 2 sigma / s: the factor of eq. 10's sum.
  int samples = 1;        ///< s of eq. 10.
  const float* ux = nullptr;  ///< s unit directions of the pattern (cos of sample i's angle).
  const float* uy = nullptr;  ///< (sin of sample i's angle).
  const float* rot_c = nullptr;  ///< Per-pixel rotations of the pattern: a table of 1024 (cos, sin).
  const float* rot_s = nullptr;
  std::uint32_t seed = 0;  ///< Picks each pixel's rotation and jitter: pixel_seed(seed, x, y).
  /// A deep G-buffer's second layer (GBuffer::second_depth, signed; its magnitude is the depth,
  /// +infinity none), or null. With it each tap also reads the second layer's point on the same
  /// pixel's ray, and the tap counts the larger of the two points' terms.
  const float* second = nullptr;
};

/// The widest row segment alchemy_row takes, pixels.
inline constexpr int kMaxAlchemySegment = 512;

/// Eq. 10 before the power k for the pixels [x0, x1) (x1 - x0 <= kMaxAlchemySegment) of row y into v[x - x0]: on covered pixels
/// max(0, 1 - scale sum_i max(0, v_i . n + z_C beta) / (v_i . v_i + epsilon)) over the s samples
/// P_i of the disk of radius r about C (stratified in s equal-area annuli, rotated and jittered per
/// pixel, read from the depth buffer, clamp-to-edge) with |v_i| < r, v_i = P_i - C; 1 elsewhere. With
/// a second layer, a tap's term is the larger of its two points'.
void alchemy_row(const AlchemyInputs& in, int y, int x0, int x1, float* v);

}  // namespace ao::simd
