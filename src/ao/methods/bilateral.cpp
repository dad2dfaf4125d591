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

// The centre pixels of one row segment: the normal, n . (ray through the pixel), the depth, and
// the reciprocal of the plane-distance scale. Positions are depth * ray (as in alchemy.cpp): the
// taps then read one float of depth each instead of a 12-byte position.
struct Centres {
  alignas(64) std::array<float, kTileWidth> nx, ny, nz, d0, inv_scale, cov;
};

void load_centres(const GBuffer& g, const Rays& rays, int y, int x0, int x1, float plane_sigma, Centres& c) {
  const std::size_t base = static_cast<std::size_t>(y) * g.width() + x0;
  const float* n = &g.normal[base].x;
  const float* depth = &g.depth[base];
  const std::uint8_t* cov = &g.coverage[base];
  const float ry = rays.y(static_cast<float>(y) + 0.5f);
  const int count = x1 - x0;
  for (int k = 0; k < count; ++k) {
    c.nx[k] = n[3 * k], c.ny[k] = n[3 * k + 1], c.nz[k] = n[3 * k + 2];
  }
  for (int k = 0; k < count; ++k) {
    const bool covered = cov[k] != 0;
    const float d = covered ? depth[k] : 0.0f;
    const float rx = rays.x(static_cast<float>(x0 + k) + 0.5f);
    // n . C with C = d * (rx, ry, -1): the centre's tangent plane is n . P = d0.
    c.d0[k] = d * (c.nx[k] * rx + c.ny[k] * ry - c.nz[k]);
    // Background: scale 0 (and cov 0), so its taps are never used.
    c.inv_scale[k] = covered ? 1.0f / (plane_sigma * d) : 0.0f;
    c.cov[k] = covered ? 1.0f : 0.0f;
  }
}

// K(x) = max(0, 1 - x^2/4)^2 with x = plane distance / scale.
inline float range_weight(float dist_scaled) {
  const float t = std::max(0.0f, 1.0f - 0.25f * dist_scaled * dist_scaled);
  return t * t;
}

// One tap, accumulated for a row segment. tdepth/tval point at the tap pixels (aligned with the
// segment's first pixel); the tap's ray is (trx[k], try_, -1).
inline void accumulate_tap(const Centres& c, int count, float spatial, const float* __restrict trx, float try_, const float* __restrict tdepth,
                           const float* __restrict tval, float* __restrict sum_w, float* __restrict sum_v) {
  for (int k = 0; k < count; ++k) {
    const float d = tdepth[k];
    const float dist = std::abs(d * (c.nx[k] * trx[k] + c.ny[k] * try_ - c.nz[k]) - c.d0[k]) * c.inv_scale[k];
    // Background taps have depth +inf: dist is inf or NaN, and the select gives them weight 0.
    const float w = d < kInfinity ? spatial * range_weight(dist) : 0.0f;
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
          load_centres(g, rays, y, x0, x1, params.plane_sigma, c);
          const std::size_t row = static_cast<std::size_t>(y) * w;
          for (int k = 0; k < n + 2 * half; ++k) {
            const int x = x0 - half + k;
            const bool in = x >= 0 && x < w;
            rd[k] = in ? depth[row + x] : kInfinity;
            rv[k] = in ? values[row + x] : 0.0f;
          }
          std::fill_n(sum_w.begin(), n, 0.0f);
          std::fill_n(sum_v.begin(), n, 0.0f);
          const float ry = rays.y(static_cast<float>(y) + 0.5f);
          for (int j = 0; j < params.taps; ++j)
            accumulate_tap(c, n, spatial[j], &rx[j], ry, &rd[j], &rv[j], sum_w.data(), sum_v.data());
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
        alignas(64) std::array<float, kTileWidth> rx, sum_w, sum_v;
        for (int k = 0; k < n; ++k) rx[k] = rays.x(static_cast<float>(x0 + k) + 0.5f);
        for (int y = r.rows().begin(); y < r.rows().end(); ++y) {
          load_centres(g, rays, y, x0, x1, params.plane_sigma, c);
          std::fill_n(sum_w.begin(), n, 0.0f);
          std::fill_n(sum_v.begin(), n, 0.0f);
          for (int j = -half; j <= half; ++j) {
            const int yj = y + j;
            if (yj < 0 || yj >= h) continue;
            const std::size_t i = static_cast<std::size_t>(yj) * w + x0;
            accumulate_tap(c, n, spatial[j + half], rx.data(), rays.y(static_cast<float>(yj) + 0.5f), &depth[i], &tmp[i], sum_w.data(),
                           sum_v.data());
          }
          const std::size_t row = static_cast<std::size_t>(y) * w + x0;
          finish(c, n, sum_w.data(), sum_v.data(), &tmp[row], &values[row]);
        }
      },
      tbb::simple_partitioner());
}

}  // namespace ao
