// SPDX-License-Identifier: Apache-2.0
#include "ao/methods/filters/bilateral.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <tbb/enumerable_thread_specific.h>

#include "ao/core/error.h"
#include "ao/core/math.h"
#include "ao/core/parallel.h"
#include "ao/core/params_table.h"
#include "ao/methods/filters/filters_kernel_internal.h"
#include "ao/simd/depth_plane.h"

namespace ao {

namespace {

constexpr int kMaxTaps = kMaxBilateralTaps;
// Tiles as wide as a typical image row so the inner loops are long and vectorise; 8 rows keep a
// tile's working set (the depths of 8 + 12 rows for the vertical pass) in L1/L2.
constexpr int kTileWidth = 512, kTileHeight = 8;

// Camera rays through pixel centres: camera_direction(px, py) = (ax * px + bx, ay * py + by, -1).
struct Rays {
  float ax, bx, ay, by;
  float x(float px) const { return ax * px + bx; }
  float y(float py) const { return ay * py + by; }
};

// The centre pixels of one row segment are folded into three coefficients per pass so that a tap
// costs two multiply-adds before the kernel (simd::bilateral_centres). With C = d0 (rx, ry, -1)
// (positions are depth * ray, as in alchemy.cpp: taps read one float of depth, not a 12-byte
// position) and a tap at depth d on the ray (tx, ty, -1), the tangent-plane distance over the
// scale, halved (K(x) = max(0, 1 - (x/2)^2)^2), is
//   x/2 = |d (n . (tx, ty, -1)) - n . C| * s/2 = |d (a t + b) - c|,  s = 1 / (plane_sigma d0),
// where t is the coordinate that varies along the pass (tx horizontally, ty vertically):
//   horizontal: a = nx s/2, b = (ny ry - nz) s/2;  vertical: a = ny s/2, b = (nx rx - nz) s/2;  c = (n . C) s/2.
void load_centres(const GBuffer& g, const float* depth_plane, const Rays& rays, int y, int x0, int x1, float plane_sigma, bool vertical,
                  simd::BilateralCentres& ce) {
  const std::size_t base = static_cast<std::size_t>(y) * g.width() + x0;
  simd::bilateral_centres(ce, &g.normal[base].x, &depth_plane[base], &g.object_id[base], x0, x1 - x0, rays.ax, rays.bx,
                          rays.y(static_cast<float>(y) + 0.5f), plane_sigma, vertical);
}

}  // namespace

const ParamTable<BilateralParams>& bilateral_param_table() {
  static const ParamTable<BilateralParams> table{"bilateral", bilateral_params<BilateralParams>("", [](BilateralParams& p) -> BilateralParams& { return p; })};
  return table;
}

void BilateralParams::validate() const {
  bilateral_param_table().validate(*this);
  if (taps % 2 == 0) throw InputError("bilateral: taps must be odd, got " + std::to_string(taps));
}
void to_json(nlohmann::json& j, const BilateralParams& p) { j = bilateral_param_table().to_json(p); }
void from_json(const nlohmann::json& j, BilateralParams& p) { bilateral_param_table().from_json(j, p); }

namespace {

// Validates the call; false when there is nothing to filter.
bool filter_wanted(const GBuffer& g, const Image<float>& values, const BilateralParams& params) {
  params.validate();
  const int w = g.width(), h = g.height();
  if (values.width() != w || values.height() != h)
    throw InputError("bilateral: the image is " + std::to_string(values.width()) + "x" + std::to_string(values.height()) +
                     " but the G-buffer is " + std::to_string(w) + "x" + std::to_string(h));
  return params.taps != 1 && !values.empty();
}

// The filter, with `depth` the G-buffer's depth_plane().
void filter(const GBuffer& g, const float* depth, Image<float>& values, const BilateralParams& params) {
  const int w = g.width(), h = g.height();
  const int half = params.taps / 2;
  std::array<float, kMaxTaps> spatial{};
  const float ss = params.effective_spatial_sigma();
  for (int j = -half; j <= half; ++j) spatial[j + half] = std::exp(-0.5f * static_cast<float>(j * j) / (ss * ss));

  const float t = g.camera.tan_half_fov(), aspect = g.camera.aspect();
  const Rays rays{2.0f * t * aspect / static_cast<float>(w), -t * aspect, -2.0f * t / static_cast<float>(h), t};

  Image<float> tmp;
  tmp.resize(w, h);  // every pixel written by the horizontal pass, in parallel
  // A row segment's centres, one set per thread for both passes (not allocated per tile).
  tbb::enumerable_thread_specific<simd::BilateralCentres> centres;
  // Horizontal pass: each row segment's depths and values are copied with `half` pixels of margin
  // on both sides (depth +inf beyond the image), so every tap is a plain shifted load.
  tbb::parallel_for(
      tbb::blocked_range2d<int>(0, h, kTileHeight, 0, w, kTileWidth),
      [&](const tbb::blocked_range2d<int>& r) {
        const int x0 = r.cols().begin(), x1 = r.cols().end(), n = x1 - x0;
        simd::BilateralCentres& c = centres.local();
        alignas(64) std::array<float, kTileWidth + 2 * kMaxTaps> rx, rd, rv;
        for (int k = 0; k < n + 2 * half; ++k) rx[k] = rays.x(static_cast<float>(x0 - half + k) + 0.5f);
        for (int y = r.rows().begin(); y < r.rows().end(); ++y) {
          load_centres(g, depth, rays, y, x0, x1, params.plane_sigma, false, c);
          const std::size_t row = static_cast<std::size_t>(y) * w;
          // Inside the image a plain copy (the per-element bounds test kept this loop scalar), margins apart.
          const int lo = std::max(0, half - x0), hi = std::min(n + 2 * half, w - x0 + half);
          std::fill(rd.begin(), rd.begin() + lo, kInfinity), std::fill(rv.begin(), rv.begin() + lo, 0.0f);
          std::copy_n(&depth[row + x0 - half + lo], hi - lo, rd.begin() + lo);
          std::copy_n(&values[row + x0 - half + lo], hi - lo, rv.begin() + lo);
          std::fill(rd.begin() + hi, rd.begin() + n + 2 * half, kInfinity), std::fill(rv.begin() + hi, rv.begin() + n + 2 * half, 0.0f);
          std::array<const float*, kMaxTaps> tt, td, tv;
          for (int j = 0; j < params.taps; ++j) tt[j] = &rx[j], td[j] = &rd[j], tv[j] = &rv[j];
          simd::bilateral_taps(c, n, params.taps, spatial.data(), tt.data(), true, td.data(), tv.data(), &values[row + x0], &tmp[row + x0]);
        }
      },
      tbb::simple_partitioner());
  // Vertical pass: taps are whole rows, so rows beyond the image are skipped as a unit.
  tbb::parallel_for(
      tbb::blocked_range2d<int>(0, h, kTileHeight, 0, w, kTileWidth),
      [&](const tbb::blocked_range2d<int>& r) {
        const int x0 = r.cols().begin(), x1 = r.cols().end(), n = x1 - x0;
        simd::BilateralCentres& c = centres.local();
        for (int y = r.rows().begin(); y < r.rows().end(); ++y) {
          load_centres(g, depth, rays, y, x0, x1, params.plane_sigma, true, c);
          std::array<const float*, kMaxTaps> tt, td, tv;
          std::array<float, kMaxTaps> ry, sp;
          int taps = 0;
          for (int j = -half; j <= half; ++j) {
            const int yj = y + j;
            if (yj < 0 || yj >= h) continue;
            const std::size_t i = static_cast<std::size_t>(yj) * w + x0;
            ry[taps] = rays.y(static_cast<float>(yj) + 0.5f);
            sp[taps] = spatial[j + half];
            tt[taps] = &ry[taps], td[taps] = &depth[i], tv[taps] = &tmp[i];
            ++taps;
          }
          const std::size_t row = static_cast<std::size_t>(y) * w + x0;
          simd::bilateral_taps(c, n, taps, sp.data(), tt.data(), false, td.data(), tv.data(), &tmp[row], &values[row]);
        }
      },
      tbb::simple_partitioner());
}

}  // namespace

void bilateral_filter(const GBuffer& g, Image<float>& values, const BilateralParams& params) {
  if (!filter_wanted(g, values, params)) return;
  const Image<float> depth = depth_plane(g);
  filter(g, depth.data(), values, params);
}

void bilateral_filter(const GBuffer& g, const Image<float>& depth, Image<float>& values, const BilateralParams& params) {
  if (!filter_wanted(g, values, params)) return;
  AO_ASSERT(depth.width() == g.width() && depth.height() == g.height());
  filter(g, depth.data(), values, params);
}

}  // namespace ao
