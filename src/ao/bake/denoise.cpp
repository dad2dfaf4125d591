// SPDX-License-Identifier: Apache-2.0
// Texture-space denoising of an AO map: see denoise.h.
#include "ao/bake/denoise.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "ao/reference/packets_internal.h"

namespace ao {

namespace {

constexpr float kPlaneTolerance = 0.5f;  // tau, texels
constexpr float kGateSlope = 2.0f, kGateSlack = 1.5f;
// k, standard deviations of the difference of two texels' values: the largest that keeps the contact
// edges of a box on a floor no softer than unfiltered at 64 rays, with a margin (RMSE over the contact
// texels 0.0078 at 1.5, 0.0086 at 1.75, 0.0098 at 2 against 0.0095 unfiltered; tests/bake/bake_test.cpp,
// docs/methods/bake.md "Denoising").
constexpr float kRangeTolerance = 1.5f;
// A standard deviation of 0.01: two texels whose samples all agreed within their strata (V = 0 or 1
// there) measure no noise, and should still take neighbours that differ by less than a 64-ray
// texel's typical noise.
constexpr float kVarianceFloor = 1e-4f;
// lambda, texels^2: the ridge on the fit's slopes (denoise.h). 0 is the plain first-order fit, whose
// estimate at a window's edge is noisier (it extrapolates); large is the weighted mean, biased
// there. 0.5 keeps the floor beside a box on a floor no worse than unfiltered at 8-64 rays and
// sigma 1 (0.0120 against 0.0124 at 64 rays; the plain fit 0.0126, the mean 0.0132), with the
// elephant's whole-map error at most 0.5% above the mean's at 12 and 24 rays, sigma 1 and 2
// (4.6% below at 24 rays, sigma 2; docs/methods/bake.md, "Denoising").
constexpr float kSlopeRidge = 0.5f;

}  // namespace

void denoise_map(Image<float>& visibility, const Image<std::uint8_t>& valid, const TexelCoverage& cov, const TexelGuides& guides, float sigma) {
  const int w = cov.width, h = cov.height;
  const int r = static_cast<int>(std::ceil(2.0f * sigma));
  const int side = 2 * r + 1;
  std::vector<float> gauss(static_cast<std::size_t>(side * side)), gate(gauss.size());
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx) {
      const auto k = static_cast<std::size_t>((dy + r) * side + dx + r);
      const float d2 = static_cast<float>(dx * dx + dy * dy);
      gauss[k] = std::exp(-d2 / (2.0f * sigma * sigma));
      const float g = kGateSlope * std::sqrt(d2) + kGateSlack;
      gate[k] = g * g;
    }
  const Image<float> in = visibility;
  const float range_scale = 1.0f / (kRangeTolerance * kRangeTolerance);
  const auto at = [w](int x, int y) { return static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x); };
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
    // The weights of far-apart neighbours underflow into denormals: flushed on every thread alike,
    // whatever mode the pool thread was left in, so the result is the same at any thread count.
    const detail::FlushDenormalsScope ftz;
    for (int y = rows.begin(); y < rows.end(); ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t c = at(x, y);
        if (!valid[c]) continue;
        const float texel_area = cov.uv_area[c] > 0 ? cov.world_area[c] / cov.uv_area[c] : 0.0f;  // h_c^2
        if (!(texel_area > 0)) continue;
        const Vec3 pc = guides.position[c], nc = guides.normal[c];
        const float vc = in[c], var_c = guides.variance[c];
        const float plane_scale = 1.0f / (kPlaneTolerance * kPlaneTolerance * texel_area);
        // The weighted moments of the fit V ~ a + b_x dx + b_y dy over the window.
        float m0 = 0, mx = 0, my = 0, mxx = 0, mxy = 0, myy = 0, s0 = 0, sx = 0, sy = 0;
        for (int dy = std::max(-r, -y); dy <= std::min(r, h - 1 - y); ++dy)
          for (int dx = std::max(-r, -x); dx <= std::min(r, w - 1 - x); ++dx) {
            const std::size_t q = at(x + dx, y + dy);
            if (!valid[q]) continue;
            const auto k = static_cast<std::size_t>((dy + r) * side + dx + r);
            const Vec3 d = guides.position[q] - pc;
            if (dot(d, d) > gate[k] * texel_area) continue;  // far on the surface: another chart
            const float off_plane = dot(d, nc);
            float cn = std::max(0.0f, dot(nc, guides.normal[q]));
            cn *= cn, cn *= cn, cn *= cn;
            const float vq = in[q], dv = vq - vc;
            const float var = var_c + guides.variance[q] + kVarianceFloor;
            const float wq = gauss[k] * std::exp(-0.5f * (off_plane * off_plane * plane_scale + dv * dv * range_scale / var)) * cn;
            const auto fx = static_cast<float>(dx), fy = static_cast<float>(dy);
            m0 += wq, mx += wq * fx, my += wq * fy, mxx += wq * fx * fx, mxy += wq * fx * fy, myy += wq * fy * fy;
            s0 += wq * vq, sx += wq * vq * fx, sy += wq * vq * fy;
          }
        if (!(m0 > 0)) continue;
        // The normal equations with the ridge lambda m0 on the slopes,
        //   [m0 mx my; mx mxx+l mxy; my mxy myy+l] (a b_x b_y) = (s0 sx sy),
        // solved for a by Cramer's rule in double. The matrix is positive definite (m0 >= 1: the
        // centre weighs 1; l > 0), so its determinant is positive; the mean stands in should
        // rounding say otherwise.
        const double l = static_cast<double>(kSlopeRidge) * m0;
        const double pxx = mxx + l, pyy = myy + l, pxy = mxy;
        const double c00 = pxx * pyy - pxy * pxy, c01 = mx * pyy - pxy * my, c02 = mx * pxy - pxx * my;
        const double det = m0 * c00 - mx * c01 + my * c02;
        const double a = det > 0 ? (s0 * c00 - mx * (sx * pyy - pxy * sy) + my * (sx * pxy - pxx * sy)) / det : s0 / m0;
        visibility[c] = static_cast<float>(std::clamp(a, 0.0, 1.0));
      }
  });
}

}  // namespace ao
