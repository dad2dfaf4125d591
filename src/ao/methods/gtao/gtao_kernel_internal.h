// SPDX-License-Identifier: Apache-2.0
// Kernel of GTAO (Jimenez, Wu, Pesce, Jarabo, "Practical Realtime Strategies for Accurate Indirect
// Occlusion", 2016: the horizon search in screen-space slices and the cosine-weighted inner
// integral of its eq. 10), written once for every SIMD target (gtao.cpp). methods/gtao.cpp derives
// the slices' directions and the samples' distances from its parameters and states the method's
// deviations; this kernel runs them for a row of pixels, covered pixels in the lanes of vectors.
#pragma once

#include <cstdint>

#include "ao/simd/depth_internal.h"

namespace ao::simd {

/// What GTAO's kernel reads: the G-buffer's depth plane, normals and ids (DepthView), and the
/// tables of the 4x4 pattern (entry (y % 4) * 4 + x % 4 of each).
struct GtaoInputs : DepthView {
  float radius = 1;  ///< R, world units.
  int slices = 1, steps = 1;
  const float* dir_c = nullptr;             ///< slices x 16: cos phi of slice k for pattern entry p, [k * 16 + p].
  const float* dir_s = nullptr;             ///< slices x 16: sin phi (screen y down).
  const float* step_t = nullptr;            ///< steps x 16: step j's fraction of the screen radius, [j * 16 + p].
  // Slabs (docs/methods/gtao.md, "Thickness"): with neither, every sample is the top of a solid
  // without end (the horizon form).
  float thickness = 0;                      ///< > 0: every sample is a slab this deep (linear depth, world units).
  const float* second = nullptr;            ///< Or the second depth layer (GBuffer::second_depth), read at `separation`.
  float separation = 0;
  const float* sector_offset = nullptr;     ///< slices x 16: the offset xi in [0, 1) of the bitmask's 32 points, [k * 16 + p].
};

/// The widest row segment gtao_row takes, pixels.
inline constexpr int kMaxGtaoSegment = 512;

/// V of the covered pixels among [x0, x1) (x1 - x0 <= kMaxGtaoSegment) of row y into v[x - x0] (the others untouched):
/// sum over slices of |n_p| a(h1, h2) / sum of |n_p| a for the open hemisphere, clamped to [0, 1],
/// with the horizons h1, h2 of each slice found among its `steps` depth samples on either side
/// within R above the tangent plane. With slabs, a is the open a times the fraction of the slice's
/// 32 bitmask points (equal shares of a) that no sample's slab covers within R.
void gtao_row(const GtaoInputs& in, int y, int x0, int x1, float* v);

}  // namespace ao::simd
