// SPDX-License-Identifier: Apache-2.0
// Internals of GTAO, not installed: its per-pixel sampling tables (gtao.cpp), shared with the GPU
// backend (src/ao/methods/gtao/gtao_gpu.cpp), which uploads them so that both sample the same slices and steps.
#pragma once

#include <array>
#include <cstdint>

#include "ao/methods/gtao/gtao.h"

namespace ao::gtao_internal {

inline constexpr int kMaxSlices = 16, kMaxSteps = 32;

/// For entry p of the 4x4 pattern ((y % 4) * 4 + x % 4): the screen direction (cos, sin of phi,
/// pixel y down) of slice k, phi = pi (k + rotation_p) / slices, and the fraction of the screen
/// radius at which step j lies, ((j + offset_p) / steps)^step_power. Rotations and offsets are
/// stratified over the 16 entries (seeded permutations and jitter); without interleaving every
/// entry holds the same seeded value.
struct Tables {
  std::array<std::array<float, 16>, kMaxSlices> dir_c{}, dir_s{};
  std::array<std::array<float, 16>, kMaxSteps> step_t{};
  std::array<std::array<float, 16>, kMaxSlices> sector_offset{};  ///< the slabs' bitmask offset xi of slice k (gtao_kernel.cpp)
};
Tables make_tables(const GtaoParams& params, std::uint32_t seed);

}  // namespace ao::gtao_internal
