// SPDX-License-Identifier: Apache-2.0
// Internals of Alchemy AO, not installed: its sample pattern (alchemy.cpp), shared with the GPU
// backend (src/ao/methods/alchemy/alchemy_gpu.cpp), which uploads these tables so that both sample the same points.
#pragma once

#include <array>

#include "ao/methods/alchemy/alchemy_shared.h"

namespace ao::alchemy_internal {

inline constexpr int kMaxSamples = 1024;
// The disk's screen radius cap and the coordinate offset (alchemy_shared.h, read by the shader too).
inline constexpr float kMaxPixelRadius = shared::kAlchemyMaxPixelRadius;
inline constexpr float kCoordOffset = shared::kAlchemyCoordOffset;
// Per-pixel rotations of the sample pattern come from a table of this many angles (no trig per
// pixel); 1024 steps of 0.35 degrees are far finer than any sample spacing.
inline constexpr int kRotations = 1024;

/// cos and sin of the kRotations angles 2 pi (i + 0.5) / kRotations; pixel (x, y) takes entry
/// hash32(pixel_seed(seed, x, y)) & (kRotations - 1).
struct RotationTable {
  std::array<float, kRotations> c, s;
};
const RotationTable& rotations();

/// The unit directions of the pattern's samples, cos and sin of i times the golden angle, i < s
/// (successive samples spread evenly in angle).
struct Directions {
  std::array<float, kMaxSamples> x{}, y{};
};
Directions sample_directions(int s);

}  // namespace ao::alchemy_internal
