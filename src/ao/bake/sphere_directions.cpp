// SPDX-License-Identifier: Apache-2.0
#include "ao/bake/sphere_directions.h"

#include <cmath>

#include "ao/core/sampling.h"

namespace ao {

namespace {

float uniform(std::uint32_t seed, std::uint32_t i, std::uint32_t k) { return to_unit_float(hash_combine(hash_combine(seed, i), k)); }

// Standard normal by Box-Muller from two uniforms; 1 - u keeps the log's argument in (0, 1].
float gaussian(std::uint32_t seed, std::uint32_t i, std::uint32_t k) {
  const float u1 = 1.0f - uniform(seed, i, 2 * k), u2 = uniform(seed, i, 2 * k + 1);
  return std::sqrt(-2.0f * std::log(u1)) * std::cos(2.0f * kPi * u2);
}

// Uniformly random rotation (Shoemake's unit quaternion from three uniforms), as a 3x3 matrix.
struct Rotation {
  Vec3 r0, r1, r2;
  Vec3 apply(Vec3 v) const { return {dot(r0, v), dot(r1, v), dot(r2, v)}; }
};
Rotation random_rotation(std::uint32_t seed) {
  const float u1 = uniform(seed, 0xffffffffu, 0), u2 = uniform(seed, 0xffffffffu, 1), u3 = uniform(seed, 0xffffffffu, 2);
  const float a = std::sqrt(1 - u1), b = std::sqrt(u1);
  const float w = a * std::sin(2 * kPi * u2), x = a * std::cos(2 * kPi * u2), y = b * std::sin(2 * kPi * u3), z = b * std::cos(2 * kPi * u3);
  return {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
          {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
          {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
}

}  // namespace

std::string_view to_string(DirectionSet s) { return s == DirectionSet::Gaussian ? "gaussian" : "fibonacci"; }

std::optional<DirectionSet> parse_direction_set(std::string_view name) {
  if (name == "gaussian") return DirectionSet::Gaussian;
  if (name == "fibonacci") return DirectionSet::Fibonacci;
  return std::nullopt;
}

std::vector<Vec3> sphere_directions(DirectionSet set, int count, std::uint32_t seed) {
  std::vector<Vec3> dirs;
  dirs.reserve(static_cast<std::size_t>(std::max(count, 0)));
  const std::uint32_t s = hash32(seed ^ 0x5bd1e995u);
  if (set == DirectionSet::Gaussian) {
    for (int i = 0; i < count; ++i) {
      Vec3 v;
      // A zero vector has probability ~0 but would have no direction: redraw with another key.
      for (std::uint32_t attempt = 0; length(v) < 1e-6f; ++attempt)
        v = {gaussian(s + attempt, static_cast<std::uint32_t>(i), 0), gaussian(s + attempt, static_cast<std::uint32_t>(i), 1),
             gaussian(s + attempt, static_cast<std::uint32_t>(i), 2)};
      dirs.push_back(normalize(v));
    }
  } else {
    // Point i at height z = 1 - (2i + 1)/n (equal-area bands) and azimuth 2 pi i / phi (the
    // golden ratio): every point has a cell of area 4 pi / n. A random rotation keeps the lattice
    // from lining up with axis-aligned geometry and makes the estimate unbiased over seeds.
    const Rotation rot = random_rotation(s);
    const double golden = (1.0 + std::sqrt(5.0)) / 2.0;
    for (int i = 0; i < count; ++i) {
      const double z = 1.0 - (2.0 * i + 1.0) / count;
      const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
      const double phi = 2.0 * 3.14159265358979323846 * std::fmod(i / golden, 1.0);
      dirs.push_back(normalize(rot.apply({static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)), static_cast<float>(z)})));
    }
  }
  return dirs;
}

}  // namespace ao
