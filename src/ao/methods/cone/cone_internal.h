// SPDX-License-Identifier: Apache-2.0
// Internals of the cone method's kernel shared by its two grids (cone.cpp: the eye grid and the
// parameters; cone_world.cpp: the world grid), not installed.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "ao/core/gbuffer.h"
#include "ao/core/progress.h"
#include "ao/methods/cone/cone.h"
#include "ao/methods/cone/cone_pattern_internal.h"
#include "ao/methods/cone/cone_shared.h"

namespace ao::cone_internal {

constexpr int kTile = 16;
// A cone stops once its transmittance T <= kOpaque (cone_shared.h, read by the shader too).
constexpr float kOpaque = shared::kConeOpaque;

// Length of [zlo, zhi) (voxel units along the column) covered by solid voxels, counting the two
// end voxels by the part of them inside the range. The paper counts whole bits (Fig. 7); the
// fractional ends remove a bias of up to a voxel per prism, which matters for the small spheres
// near the apex whose chords are a few voxels long.
inline float solid_length(const std::uint64_t* col, int words, int nbits, float zlo, float zhi) {
  zlo = std::max(zlo, 0.0f);
  zhi = std::min(zhi, static_cast<float>(nbits));
  if (!(zhi > zlo)) return 0.0f;
  const int k0 = static_cast<int>(zlo);
  const int k1 = std::min(static_cast<int>(zhi), nbits - 1);
  const auto bit = [&](int k) { return static_cast<float>((col[k >> 6] >> (k & 63)) & 1u); };
  if (k0 >= k1) return bit(k0) * (zhi - zlo);
  // Whole voxels strictly between the end voxels: bitfieldExtract + bitCount of Fig. 7.
  return bit(k0) * (static_cast<float>(k0 + 1) - zlo) + static_cast<float>(count_bits(col, words, k0 + 1, k1)) +
         bit(k1) * (zhi - static_cast<float>(k1));
}

// The kernel on a world grid (docs/methods/cone.md, Speed): V for every covered pixel of `gb`,
// 1 elsewhere; `setup` and `pat` from derive_cone_setup and make_cone_pattern.
void trace_world(const GBuffer& gb, const VoxelGrid& g, float r_max, const ConeSetup& setup, const ConePattern& pat, ImageView<float> out,
                 const ProgressFn& progress);

}  // namespace ao::cone_internal
