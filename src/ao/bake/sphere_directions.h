// SPDX-License-Identifier: Apache-2.0
// Direction sets on the unit sphere for outside-in baking (the per-texel AO paper, sec. 3:
// "Uniformly distributed unit vectors can be produced by drawing each component from a zero mean
// normal distribution and normalizing the vector"), and a stratified alternative.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "ao/core/math.h"

namespace ao {

enum class DirectionSet {
  Gaussian,   ///< The paper's: i.i.d. normalised Gaussian vectors (Devroye), seeded hash per direction.
  Fibonacci,  ///< Spherical Fibonacci lattice (stratified, near-equal areas), randomly rotated by the seed.
};

std::string_view to_string(DirectionSet s);
std::optional<DirectionSet> parse_direction_set(std::string_view name);

/// `count` unit directions uniformly distributed on the sphere (each set's expectation is the
/// uniform measure), deterministic in `seed`.
std::vector<Vec3> sphere_directions(DirectionSet set, int count, std::uint32_t seed);

}  // namespace ao
