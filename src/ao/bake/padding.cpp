// SPDX-License-Identifier: Apache-2.0
// Based on the seam fix of McGraw & Sowers (sec. 3.3): "the first dilation step replaces the
// boundary pixels with the nearest valid AO value, and the second step expands the AO map by 1
// pixel further so that bilinear texture filtering will be correct". Padding is the same dilation
// repeated `margin` times, so mipmaps (not only bilinear filtering) stay clear of the background.
// Each dilation ring takes, for every newly reached texel, the source texel of the neighbour whose
// source is nearest in Euclidean distance: nearest-texel padding, not a blur.
#include "ao/bake/padding.h"

#include <vector>

namespace ao {

Image<std::int32_t> nearest_valid_texel(const Image<std::uint8_t>& valid, int margin) {
  const int w = valid.width(), h = valid.height();
  Image<std::int32_t> src(w, h, -1);
  std::vector<std::int32_t> front;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (valid(x, y)) {
        src(x, y) = y * w + x;
        front.push_back(y * w + x);
      }
  std::vector<std::int32_t> next;
  std::vector<std::int32_t> ring_src;
  for (int ring = 0; ring < margin && !front.empty(); ++ring) {
    // Candidates: unassigned 8-neighbours of the front. Decide all of this ring from the previous
    // rings only, so the result does not depend on the order texels are visited.
    next.clear();
    for (std::int32_t i : front) {
      const int x = i % w, y = i / w;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= w || ny >= h || src(nx, ny) != -1) continue;
          src(nx, ny) = -2;  // queued for this ring
          next.push_back(ny * w + nx);
        }
    }
    ring_src.assign(next.size(), -1);
    for (std::size_t k = 0; k < next.size(); ++k) {
      const int x = next[k] % w, y = next[k] / w;
      long best_d = -1;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          const std::int32_t s = src(nx, ny);
          if (s < 0) continue;
          const long sx = s % w - x, sy = s / w - y;
          const long d = sx * sx + sy * sy;
          if (best_d < 0 || d < best_d || (d == best_d && s < ring_src[k])) {
            best_d = d;
            ring_src[k] = s;
          }
        }
    }
    for (std::size_t k = 0; k < next.size(); ++k) src[static_cast<std::size_t>(next[k])] = ring_src[k];
    front.swap(next);
  }
  return src;
}

template <class T>
static void pad_impl(Image<T>& image, const Image<std::int32_t>& nearest) {
  for (std::size_t i = 0; i < image.size(); ++i) {
    const std::int32_t s = nearest[i];
    if (s >= 0 && static_cast<std::size_t>(s) != i) image[i] = image[static_cast<std::size_t>(s)];
  }
}

void pad(Image<float>& image, const Image<std::int32_t>& nearest) { pad_impl(image, nearest); }
void pad(Image<Vec3>& image, const Image<std::int32_t>& nearest) { pad_impl(image, nearest); }

Image<std::uint8_t> erode(const Image<std::uint8_t>& mask) {
  const int w = mask.width(), h = mask.height();
  Image<std::uint8_t> out(w, h, std::uint8_t{0});
  auto at = [&](int x, int y) { return x >= 0 && y >= 0 && x < w && y < h && mask(x, y) != 0; };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      out(x, y) = at(x, y) && at(x - 1, y) && at(x + 1, y) && at(x, y - 1) && at(x, y + 1) ? 1 : 0;
  return out;
}

}  // namespace ao
