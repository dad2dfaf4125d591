// SPDX-License-Identifier: Apache-2.0
// Based on the seam fix of McGraw & Sowers (sec. 3.3): "the first dilation step replaces the
// boundary pixels with the nearest valid AO value, and the second step expands the AO map by 1
// pixel further so that bilinear texture filtering will be correct". Padding is the same dilation
// repeated `margin` times, so mipmaps (not only bilinear filtering) stay clear of the background.
// Each dilation ring takes, for every newly reached texel, the source texel of the neighbour whose
// source is nearest in Euclidean distance: nearest-texel padding, not a blur.
#include "ao/bake/padding.h"

#include <vector>

#include "ao/core/error.h"

namespace ao {

namespace {

// The rings work on texel coordinates packed in 31 bits, x in the low 16 and y above (images are at
// most kMaxImageSide = 32768 texels a side), so that a source's distance needs no division of its
// index by the width, and packed values order as indices do (y, then x).
std::int32_t pack(int x, int y) { return static_cast<std::int32_t>(static_cast<std::uint32_t>(x) | static_cast<std::uint32_t>(y) << 16); }
int unpack_x(std::int32_t p) { return static_cast<int>(static_cast<std::uint32_t>(p) & 0xffffu); }
int unpack_y(std::int32_t p) { return static_cast<int>(static_cast<std::uint32_t>(p) >> 16); }
constexpr std::int32_t kUnassigned = -1, kQueued = -2;  // below every packed texel

}  // namespace

Image<std::int32_t> nearest_valid_texel(const Image<std::uint8_t>& valid, int margin) {
  const int w = valid.width(), h = valid.height();
  AO_ASSERT(w <= 65536 && h <= 32768);  // what pack holds; images are at most kMaxImageSide a side
  // Each texel's source, packed, or kUnassigned / kQueued; made into indices at the end, in place.
  Image<std::int32_t> source(w, h, kUnassigned);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (valid(x, y)) source(x, y) = pack(x, y);
  // The first front: the valid texels with an 8-neighbour that is not (only they can reach an
  // unassigned texel).
  std::vector<std::int32_t> front, next;
  const auto assigned = [&](int x, int y) { return x < 0 || y < 0 || x >= w || y >= h || source(x, y) != kUnassigned; };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (valid(x, y) && !(assigned(x - 1, y - 1) && assigned(x, y - 1) && assigned(x + 1, y - 1) && assigned(x - 1, y) &&
                           assigned(x + 1, y) && assigned(x - 1, y + 1) && assigned(x, y + 1) && assigned(x + 1, y + 1)))
        front.push_back(pack(x, y));
  std::vector<std::int32_t> ring_source;
  for (int ring = 0; ring < margin && !front.empty(); ++ring) {
    // Candidates: unassigned 8-neighbours of the front. Decide all of this ring from the previous
    // rings only, so the result does not depend on the order texels are visited.
    next.clear();
    for (const std::int32_t p : front) {
      const int x = unpack_x(p), y = unpack_y(p);
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= w || ny >= h || source(nx, ny) != kUnassigned) continue;
          source(nx, ny) = kQueued;
          next.push_back(pack(nx, ny));
        }
    }
    // Each candidate takes the source, among its assigned neighbours' sources, nearest to it; of
    // equally near ones the first in index order. (Every candidate has one: the texel that queued it.)
    ring_source.resize(next.size());
    for (std::size_t k = 0; k < next.size(); ++k) {
      const int x = unpack_x(next[k]), y = unpack_y(next[k]);
      long best_d = -1;
      std::int32_t best = kUnassigned;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          const std::int32_t s = source(nx, ny);
          if (s < 0) continue;
          const long sx = unpack_x(s) - x, sy = unpack_y(s) - y;
          const long d = sx * sx + sy * sy;
          if (best_d < 0 || d < best_d || (d == best_d && s < best)) best_d = d, best = s;
        }
      ring_source[k] = best;
    }
    for (std::size_t k = 0; k < next.size(); ++k) source(unpack_x(next[k]), unpack_y(next[k])) = ring_source[k];
    front.swap(next);
  }
  for (std::size_t i = 0; i < source.size(); ++i)
    if (const std::int32_t s = source[i]; s >= 0) source[i] = unpack_y(s) * w + unpack_x(s);  // < 2^31: the image's texel count
  return source;
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
