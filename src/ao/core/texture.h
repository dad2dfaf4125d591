// SPDX-License-Identifier: Apache-2.0
// Texture lookup in UV space, with the convention of the AO maps `ao bake` writes and of OpenGL:
// u runs left to right, v bottom to top, so texel (x, y) of a w x h image covers
// u in [x/w, (x+1)/w] and v in [1 - (y+1)/h, 1 - y/h].
#pragma once

#include <algorithm>
#include <cmath>

#include "ao/core/image.h"
#include "ao/core/math.h"

namespace ao {

/// Bilinear lookup of `map` at `uv`, clamped to the edge texels (AO maps are padded beyond their
/// charts, so clamping is what a viewer with clamp-to-edge sampling shows). `map` must not be empty.
inline float sample_bilinear(const Image<float>& map, Vec2 uv) {
  const int w = map.width(), h = map.height();
  // Texel centres sit at (x + 0.5) / w.
  const float fx = std::clamp(uv.x * static_cast<float>(w) - 0.5f, 0.0f, static_cast<float>(w - 1));
  const float fy = std::clamp((1.0f - uv.y) * static_cast<float>(h) - 0.5f, 0.0f, static_cast<float>(h - 1));
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
  const float tx = fx - static_cast<float>(x0), ty = fy - static_cast<float>(y0);
  const float top = map(x0, y0) * (1 - tx) + map(x1, y0) * tx;
  const float bottom = map(x0, y1) * (1 - tx) + map(x1, y1) * tx;
  return top * (1 - ty) + bottom * ty;
}

}  // namespace ao
