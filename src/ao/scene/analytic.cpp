// SPDX-License-Identifier: Apache-2.0
#include "ao/scene/analytic.h"

namespace ao {

Image<float> make_bump_map(int size, int bumps) {
  // A grid of bumps x bumps smooth domes, h = cos^2 of the distance to the cell centre scaled so the
  // dome ends at the cell's inscribed circle: heights in [0, 1], C1 continuous, periodic.
  Image<float> map(size, size, 0.0f);
  const float cell = static_cast<float>(size) / static_cast<float>(bumps);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const float u = std::fmod((static_cast<float>(x) + 0.5f), cell) / cell - 0.5f;
      const float v = std::fmod((static_cast<float>(y) + 0.5f), cell) / cell - 0.5f;
      const float r = std::sqrt(u * u + v * v) * 2.0f;  // 1 at the inscribed circle
      const float c = r < 1.0f ? std::cos(0.5f * kPi * r) : 0.0f;
      map(x, y) = c * c;
    }
  return map;
}

}  // namespace ao
