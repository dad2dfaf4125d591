// SPDX-License-Identifier: Apache-2.0
#include "ao/eval/metrics.h"

#include <cmath>
#include <string>
#include <vector>

#include "ao/core/error.h"

namespace ao {

namespace {

bool selected(const Image<std::uint8_t>& mask, std::size_t i) { return mask.empty() || mask[i] != 0; }

// SSIM of Wang, Bovik, Sheikh and Simoncelli (2004) with their constants for a dynamic range of 1:
// C1 = (0.01)^2, C2 = (0.03)^2, and their 11x11 Gaussian window with sigma 1.5, renormalised over
// the masked pixels inside each window.
double mean_ssim(const Image<float>& a, const Image<float>& b, const Image<std::uint8_t>& mask) {
  constexpr int kRadius = 5;
  constexpr double kSigma = 1.5, kC1 = 0.01 * 0.01, kC2 = 0.03 * 0.03;
  double weights[2 * kRadius + 1];
  for (int i = -kRadius; i <= kRadius; ++i) weights[i + kRadius] = std::exp(-(i * i) / (2 * kSigma * kSigma));
  const int w = a.width(), h = a.height();
  double sum = 0;
  std::size_t count = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t c = static_cast<std::size_t>(y) * w + x;
      if (!selected(mask, c)) continue;
      double sw = 0, ma = 0, mb = 0, saa = 0, sbb = 0, sab = 0;
      for (int dy = -kRadius; dy <= kRadius; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= h) continue;
        for (int dx = -kRadius; dx <= kRadius; ++dx) {
          const int xx = x + dx;
          if (xx < 0 || xx >= w) continue;
          const std::size_t i = static_cast<std::size_t>(yy) * w + xx;
          if (!selected(mask, i)) continue;
          const double wt = weights[dy + kRadius] * weights[dx + kRadius];
          const double va = a[i], vb = b[i];
          sw += wt;
          ma += wt * va;
          mb += wt * vb;
          saa += wt * va * va;
          sbb += wt * vb * vb;
          sab += wt * va * vb;
        }
      }
      ma /= sw;
      mb /= sw;
      const double va = std::max(0.0, saa / sw - ma * ma), vb = std::max(0.0, sbb / sw - mb * mb), cov = sab / sw - ma * mb;
      sum += ((2 * ma * mb + kC1) * (2 * cov + kC2)) / ((ma * ma + mb * mb + kC1) * (va + vb + kC2));
      ++count;
    }
  return count ? sum / static_cast<double>(count) : 1.0;
}

void check_sizes(const Image<float>& a, const Image<float>& b, const Image<std::uint8_t>& mask) {
  if (a.width() != b.width() || a.height() != b.height())
    throw InputError("compare: image is " + std::to_string(a.width()) + "x" + std::to_string(a.height()) + ", reference is " +
                     std::to_string(b.width()) + "x" + std::to_string(b.height()));
  if (!mask.empty() && (mask.width() != a.width() || mask.height() != a.height())) throw InputError("compare: mask size differs from the images");
}

}  // namespace

void to_json(nlohmann::json& j, const ErrorMetrics& m) {
  j = {{"rmse", m.rmse}, {"psnr_db", std::isfinite(m.psnr_db) ? nlohmann::json(m.psnr_db) : nlohmann::json("inf")}, {"ssim", m.ssim},
       {"mean_signed_error", m.mean_signed}, {"max_abs_error", m.max_abs}, {"pixels", m.pixels}};
}

ErrorMetrics compare_images(const Image<float>& image, const Image<float>& reference, const Image<std::uint8_t>& mask) {
  check_sizes(image, reference, mask);
  ErrorMetrics m;
  double se = 0, signed_sum = 0;
  for (std::size_t i = 0; i < image.size(); ++i) {
    if (!selected(mask, i)) continue;
    const double d = static_cast<double>(image[i]) - reference[i];
    se += d * d;
    signed_sum += d;
    m.max_abs = std::max(m.max_abs, std::abs(d));
    ++m.pixels;
  }
  if (m.pixels == 0) return m;
  const double mse = se / static_cast<double>(m.pixels);
  m.rmse = std::sqrt(mse);
  m.psnr_db = mse > 0 ? 10.0 * std::log10(1.0 / mse) : kInfinity;
  m.mean_signed = signed_sum / static_cast<double>(m.pixels);
  m.ssim = mean_ssim(image, reference, mask);
  return m;
}

Vec3 signed_error_colour(float error, float range) {
  const float t = std::clamp(error / range, -1.0f, 1.0f);
  // White at zero, towards red (too bright) or blue (too dark).
  return t >= 0 ? Vec3{1.0f, 1.0f - t, 1.0f - t} : Vec3{1.0f + t, 1.0f + t, 1.0f};
}

Image<Vec3> signed_error_heat_map(const Image<float>& image, const Image<float>& reference, const Image<std::uint8_t>& mask, float range) {
  check_sizes(image, reference, mask);
  Image<Vec3> out(image.width(), image.height(), Vec3{0.5f, 0.5f, 0.5f});
  for (std::size_t i = 0; i < image.size(); ++i) {
    if (!selected(mask, i)) continue;
    out[i] = signed_error_colour(image[i] - reference[i], range);
  }
  return out;
}

}  // namespace ao
