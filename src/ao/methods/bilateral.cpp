#include "ao/methods/bilateral.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "ao/core/error.h"
#include "ao/core/math.h"
#include "ao/core/parallel.h"

namespace ao {

namespace {

constexpr int kMaxTaps = 63;
// Tiles as wide as a typical image row so the inner loops are long and vectorise; 8 rows keep a
// tile's working set (the depths of 8 + 12 rows for the vertical pass) in L1/L2.
constexpr int kTileWidth = 512, kTileHeight = 8;

// Camera rays through pixel centres: camera_direction(px, py) = (ax * px + bx, ay * py + by, -1).
struct Rays {
  float ax, bx, ay, by;
  float x(float px) const { return ax * px + bx; }
  float y(float py) const { return ay * py + by; }
};

// The centre pixels of one row segment, folded into three coefficients per pass so that a tap
// costs two FMAs before the kernel. With C = d0 (rx, ry, -1) (positions are depth * ray, as in
// alchemy.cpp: taps read one float of depth, not a 12-byte position) and a tap at depth d on the
// ray (tx, ty, -1), the tangent-plane distance over the scale, halved (K(x) = max(0, 1 - (x/2)^2)^2), is
//   x/2 = |d (n . (tx, ty, -1)) - n . C| * s/2 = |d (a t + b) - c|,  s = 1 / (plane_sigma d0),
// where t is the coordinate that varies along the pass (tx horizontally, ty vertically):
//   horizontal: a = nx s/2, b = (ny ry - nz) s/2;  vertical: a = ny s/2, b = (nx rx - nz) s/2;  c = (n . C) s/2.
struct Centres {
  alignas(64) std::array<float, kTileWidth> a, b, c, cov;
};

void load_centres(const GBuffer& g, const Rays& rays, int y, int x0, int x1, float plane_sigma, bool vertical, Centres& ce) {
  const std::size_t base = static_cast<std::size_t>(y) * g.width() + x0;
  const float* n = &g.normal[base].x;
  const float* depth = &g.depth[base];
  const std::uint8_t* cov = &g.coverage[base];
  const float ry = rays.y(static_cast<float>(y) + 0.5f);
  const int count = x1 - x0;
  for (int k = 0; k < count; ++k) {
    const float nx = n[3 * k], ny = n[3 * k + 1], nz = n[3 * k + 2];
    const bool covered = cov[k] != 0;
    const float d = covered ? depth[k] : 0.0f;
    const float rx = rays.x(static_cast<float>(x0 + k) + 0.5f);
    // Background: scale 0 (and cov 0), so its result is never used.
    const float half_s = covered ? 0.5f / (plane_sigma * d) : 0.0f;
    ce.a[k] = (vertical ? ny : nx) * half_s;
    ce.b[k] = (vertical ? nx * rx - nz : ny * ry - nz) * half_s;
    ce.c[k] = d * (nx * rx + ny * ry - nz) * half_s;
    ce.cov[k] = covered ? 1.0f : 0.0f;
  }
}

// One tap, accumulated for a row segment. tdepth/tval point at the tap pixels (aligned with the
// segment's first pixel); the tap's varying ray coordinate is t[k] (horizontal: per pixel) or
// t[0] (vertical: one value for the whole row).
template <bool kPerPixel>
inline void accumulate_tap(const Centres& ce, int count, float spatial, const float* __restrict t, const float* __restrict tdepth,
                           const float* __restrict tval, float* __restrict sum_w, float* __restrict sum_v) {
  for (int k = 0; k < count; ++k) {
    const float d = tdepth[k];
    const float half_x = d * (ce.a[k] * t[kPerPixel ? k : 0] + ce.b[k]) - ce.c[k];
    // K = max(0, 1 - (x/2)^2)^2. Background taps have depth +inf: x is inf or NaN, and the select
    // gives them weight 0.
    const float u = std::max(0.0f, 1.0f - half_x * half_x);
    const float w = d < kInfinity ? spatial * (u * u) : 0.0f;
    sum_w[k] += w;
    sum_v[k] += w * tval[k];
  }
}

inline void finish(const Centres& c, int count, const float* sum_w, const float* sum_v, const float* in, float* out) {
  // The centre tap has weight spatial(0) * 1 > 0 on covered pixels, so sum_w > 0 there.
  for (int k = 0; k < count; ++k) out[k] = c.cov[k] > 0 ? sum_v[k] / sum_w[k] : in[k];
}

}  // namespace

void BilateralParams::validate() const {
  if (taps < 1 || taps > kMaxTaps || taps % 2 == 0)
    throw InputError("bilateral: taps must be odd and in [1, " + std::to_string(kMaxTaps) + "], got " + std::to_string(taps));
  if (!(spatial_sigma >= 0.0f) || !std::isfinite(spatial_sigma)) throw InputError("bilateral: spatial_sigma must be >= 0 pixels (0 = taps / 4)");
  if (!(plane_sigma > 0.0f) || !std::isfinite(plane_sigma)) throw InputError("bilateral: plane_sigma must be > 0 (a fraction of depth)");
}

void to_json(nlohmann::json& j, const BilateralParams& p) {
  j = {{"taps", p.taps}, {"spatial_sigma", p.spatial_sigma}, {"plane_sigma", p.plane_sigma}};
}

void from_json(const nlohmann::json& j, BilateralParams& p) {
  if (!j.is_object()) throw InputError("bilateral: parameters must be a JSON object");
  for (const auto& [key, value] : j.items())
    if (key != "taps" && key != "spatial_sigma" && key != "plane_sigma") throw InputError("bilateral: unknown parameter '" + key + "'");
  try {
    if (j.contains("taps")) p.taps = j.at("taps").get<int>();
    if (j.contains("spatial_sigma")) p.spatial_sigma = j.at("spatial_sigma").get<float>();
    if (j.contains("plane_sigma")) p.plane_sigma = j.at("plane_sigma").get<float>();
  } catch (const nlohmann::json::exception& e) {
    throw InputError(std::string("bilateral: bad parameter type: ") + e.what());
  }
}

void bilateral_filter(const GBuffer& g, Image<float>& values, const BilateralParams& params) {
  params.validate();
  const int w = g.width(), h = g.height();
  if (values.width() != w || values.height() != h)
    throw InputError("bilateral: the image is " + std::to_string(values.width()) + "x" + std::to_string(values.height()) +
                     " but the G-buffer is " + std::to_string(w) + "x" + std::to_string(h));
  if (params.taps == 1 || values.empty()) return;
  const int half = params.taps / 2;
  std::array<float, kMaxTaps> spatial{};
  const float ss = params.effective_spatial_sigma();
  for (int j = -half; j <= half; ++j) spatial[j + half] = std::exp(-0.5f * static_cast<float>(j * j) / (ss * ss));

  const float t = g.camera.tan_half_fov(), aspect = g.camera.aspect();
  const Rays rays{2.0f * t * aspect / static_cast<float>(w), -t * aspect, -2.0f * t / static_cast<float>(h), t};
  const float* depth = g.depth.data();

  Image<float> tmp(w, h);
  // Horizontal pass: each row segment's depths and values are copied with `half` pixels of margin
  // on both sides (depth +inf beyond the image), so every tap is a plain shifted load.
  tbb::parallel_for(
      tbb::blocked_range2d<int>(0, h, kTileHeight, 0, w, kTileWidth),
      [&](const tbb::blocked_range2d<int>& r) {
        const int x0 = r.cols().begin(), x1 = r.cols().end(), n = x1 - x0;
        Centres c;
        alignas(64) std::array<float, kTileWidth + 2 * kMaxTaps> rx, rd, rv;
        alignas(64) std::array<float, kTileWidth> sum_w, sum_v;
        for (int k = 0; k < n + 2 * half; ++k) rx[k] = rays.x(static_cast<float>(x0 - half + k) + 0.5f);
        for (int y = r.rows().begin(); y < r.rows().end(); ++y) {
          load_centres(g, rays, y, x0, x1, params.plane_sigma, false, c);
          const std::size_t row = static_cast<std::size_t>(y) * w;
          // Inside the image a plain copy (the per-element bounds test kept this loop scalar), margins apart.
          const int lo = std::max(0, half - x0), hi = std::min(n + 2 * half, w - x0 + half);
          std::fill(rd.begin(), rd.begin() + lo, kInfinity), std::fill(rv.begin(), rv.begin() + lo, 0.0f);
          std::copy_n(&depth[row + x0 - half + lo], hi - lo, rd.begin() + lo);
          std::copy_n(&values[row + x0 - half + lo], hi - lo, rv.begin() + lo);
          std::fill(rd.begin() + hi, rd.begin() + n + 2 * half, kInfinity), std::fill(rv.begin() + hi, rv.begin() + n + 2 * half, 0.0f);
          std::fill_n(sum_w.begin(), n, 0.0f);
          std::fill_n(sum_v.begin(), n, 0.0f);
          for (int j = 0; j < params.taps; ++j)
            accumulate_tap<true>(c, n, spatial[j], &rx[j], &rd[j], &rv[j], sum_w.data(), sum_v.data());
          finish(c, n, sum_w.data(), sum_v.data(), &values[row + x0], &tmp[row + x0]);
        }
      },
      tbb::simple_partitioner());
  // Vertical pass: taps are whole rows, so rows beyond the image are skipped as a unit.
  tbb::parallel_for(
      tbb::blocked_range2d<int>(0, h, kTileHeight, 0, w, kTileWidth),
      [&](const tbb::blocked_range2d<int>& r) {
        const int x0 = r.cols().begin(), x1 = r.cols().end(), n = x1 - x0;
        Centres c;
        alignas(64) std::array<float, kTileWidth> sum_w, sum_v;
        for (int y = r.rows().begin(); y < r.rows().end(); ++y) {
          load_centres(g, rays, y, x0, x1, params.plane_sigma, true, c);
          std::fill_n(sum_w.begin(), n, 0.0f);
          std::fill_n(sum_v.begin(), n, 0.0f);
          for (int j = -half; j <= half; ++j) {
            const int yj = y + j;
            if (yj < 0 || yj >= h) continue;
            const std::size_t i = static_cast<std::size_t>(yj) * w + x0;
            const float ry = rays.y(static_cast<float>(yj) + 0.5f);
            accumulate_tap<false>(c, n, spatial[j + half], &ry, &depth[i], &tmp[i], sum_w.data(), sum_v.data());
          }
          const std::size_t row = static_cast<std::size_t>(y) * w + x0;
          finish(c, n, sum_w.data(), sum_v.data(), &tmp[row], &values[row]);
        }
      },
      tbb::simple_partitioner());
}

}  // namespace ao
