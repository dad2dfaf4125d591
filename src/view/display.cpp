// SPDX-License-Identifier: Apache-2.0
#include "view/display.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "ao/eval/metrics.h"
#include "ao/eval/shading.h"

namespace ao::view {

namespace {

std::uint8_t to_byte(float v) {
  // As the PNG writer quantises linear V (io/image_io.cpp: lround(c * 255) of the clamped value).
  // For c * 255 in [0, 255] the double sum c * 255 + 0.5 is exact, so truncating it is lround,
  // without its libm call per channel. NaN lands on 0.
  const float c = v > 0.0f ? std::min(v, 1.0f) : 0.0f;
  return static_cast<std::uint8_t>(static_cast<int>(static_cast<double>(c * 255.0f) + 0.5));
}

// IEC 61966-2-1, as the PNG writer encodes --shaded pictures.
float srgb(float v) { return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f; }

bool present(const Image<float>* i) { return i && !i->empty(); }
bool present(const Image<Vec3>* i) { return i && !i->empty(); }

// One RGBA pixel of the colour views; display_background where no surface is visible.
Vec3 colour_at(const DisplayInputs& in, int x, int y, bool right_of_wipe, bool have_ref) {
  const std::size_t i = static_cast<std::size_t>(y) * in.gbuffer->width() + x;
  if (!in.gbuffer->covered(i)) {
    const float b = display_background(x, y);
    return {b, b, b};
  }
  if (in.view == ViewMode::Error) {
    if (have_ref && present(in.method)) return signed_error_colour((*in.method)[i] - (*in.reference)[i], kHeatRange);
    return {1, 1, 1};
  }
  if (right_of_wipe) {
    const float v = (*in.reference)[i];
    return {v, v, v};
  }
  if (in.view == ViewMode::Transfer && present(in.color)) return (*in.color)[i];
  if (in.view == ViewMode::Shaded && present(in.shaded)) {
    const Vec3 s = (*in.shaded)[i];
    return {srgb(s.x), srgb(s.y), srgb(s.z)};
  }
  if (present(in.method)) {
    const float v = (*in.method)[i];
    return {v, v, v};
  }
  return {1, 1, 1};
}

}  // namespace

bool grey_view(ViewMode view) { return view == ViewMode::AO || view == ViewMode::Map; }

void build_display(std::vector<std::uint8_t>& pixels, const DisplayInputs& in, int x0) {
  const int w = in.gbuffer->width(), h = in.gbuffer->height();
  const bool grey = grey_view(in.view);
  const int channels = grey ? 1 : 4;
  pixels.resize(static_cast<std::size_t>(w) * h * channels);
  const bool have_ref = present(in.reference) && in.reference->width() == w && in.reference->height() == h;
  const int split = have_ref ? static_cast<int>(std::lround(in.wipe * w)) : w;
  const bool map = in.view == ViewMode::Map && present(in.map);
  tbb::parallel_for(tbb::blocked_range<int>(0, h, 8), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      const std::size_t row = static_cast<std::size_t>(y) * w;
      std::uint8_t* out = &pixels[row * channels];
      if (grey) {
        // Method side, then reference side: two plain loops.
        const float* v = map ? &(*in.map)[row] : present(in.method) ? &(*in.method)[row] : nullptr;
        for (int x = x0; x < std::min(split, w); ++x) out[x] = v ? to_byte(v[x]) : 255;
        for (int x = std::max(x0, split); x < w; ++x) out[x] = to_byte((*in.reference)[row + x]);
        const std::uint32_t* id = &in.gbuffer->object_id[row];
        for (int x = x0; x < w; ++x)
          if (id[x] == 0) out[x] = to_byte(display_background(x, y));
        continue;
      }
      for (int x = x0; x < w; ++x) {
        const Vec3 c = colour_at(in, x, y, x >= split, have_ref);
        std::uint8_t* px = out + 4 * x;
        px[0] = to_byte(c.x), px[1] = to_byte(c.y), px[2] = to_byte(c.z), px[3] = 255;
      }
    }
  });
}

}  // namespace ao::view
