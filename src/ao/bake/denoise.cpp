// SPDX-License-Identifier: Apache-2.0
// Texture-space denoising of an AO map: see denoise.h.
#include "ao/bake/denoise.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "ao/bake/denoise_internal.h"
#include "ao/simd/denormals_internal.h"

namespace ao {

namespace {

constexpr float kPlaneTolerance = 0.5f;  // tau, texels
constexpr float kGateSlope = 2.0f, kGateSlack = 1.5f;
// The value term's test runs in two passes (denoise.h): the first, at sigma_g = 1 texel, compares
// the texels' own values with k_g standard deviations of their difference; the second, at the
// requested sigma, compares that first pass's values (the guide), with k. k_g = 1.5 is the filter's
// one-pass k, the largest that kept the box-on-floor contact no softer than unfiltered at 64 rays;
// k = 2 the largest of 1.5, 2, 2.5 and 3 that keeps it at or below unfiltered with a margin at 8-64
// rays and sigma 1 (0.0105 against 0.0124 at 64 rays; 2.5: 0.0122, 3: 0.0147), for 5-15% lower
// error over the elephant's whole map (docs/methods/bake.md, "Denoising").
constexpr float kGuideSigma = 1.0f;
constexpr float kGuideRangeTolerance = 1.5f;
constexpr float kRangeTolerance = 2.0f;
// A standard deviation of 0.01: two texels whose samples all agreed within their strata (V = 0 or 1
// there) measure no noise, and should still take neighbours that differ by less than a 64-ray
// texel's typical noise.
constexpr float kVarianceFloor = 1e-4f;
// lambda, texels^2: the ridge on the fit's slopes (denoise.h). 0 is the plain first-order fit, whose
// estimate at a window's edge is noisier (it extrapolates); large is the weighted mean, biased
// there. 0.5 keeps the floor beside a box on a floor no worse than unfiltered at 8-64 rays and
// sigma 1 (0.0120 against 0.0124 at 64 rays; the plain fit 0.0126, the mean 0.0132), with the
// elephant's whole-map error at most 0.5% above the mean's at 12 and 24 rays, sigma 1 and 2
// (4.6% below at 24 rays, sigma 2; docs/methods/bake.md, "Denoising"). Measured with the one-pass
// filter, whose value term compared the raw values.
constexpr float kSlopeRidge = 0.5f;

// One pass of the filter at `sigma` over `value` (the variance of each texel's value: `variance`),
// its value term comparing `guide` (variance `guide_variance`; both null: the values themselves)
// with k = `range_tolerance`. Values and variances other than the map's are per guide slot.
struct PassInputs {
  const Image<float>& value;
  const std::vector<float>& variance;
  const std::vector<float>* guide;
  const std::vector<float>* guide_variance;
  float sigma, range_tolerance;
};

// Where a pass writes its results: into the map `map`, or per guide slot into `value` and the
// variance of each result into `variance` (the first pass's guide). A texel the pass leaves as it
// is (its fit has no weight) keeps what the output held: the map's own value, or in the slots the
// texel's own value and variance.
struct PassOutputs {
  Image<float>* map = nullptr;
  std::vector<float>* value = nullptr;
  std::vector<float>* variance = nullptr;
};

void filter_pass(const PassInputs& in, const Image<std::uint8_t>& valid, const TexelCoverage& cov, const TexelGuides& guides,
                 const PassOutputs& out) {
  const int w = cov.width, h = cov.height;
  const int r = static_cast<int>(std::ceil(2.0f * in.sigma));
  const int side = 2 * r + 1;
  std::vector<float> gauss(static_cast<std::size_t>(side * side)), gate(gauss.size());
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx) {
      const auto k = static_cast<std::size_t>((dy + r) * side + dx + r);
      const float d2 = static_cast<float>(dx * dx + dy * dy);
      gauss[k] = std::exp(-d2 / (2.0f * in.sigma * in.sigma));
      const float g = kGateSlope * std::sqrt(d2) + kGateSlack;
      gate[k] = g * g;
    }
  // The rows are filtered in bands of kBandRows, each laid out as planes with r rows and columns of
  // border (denoise_internal.h) from the pass's inputs, so a texel's result does not depend on the
  // band it falls in, nor on the thread count.
  constexpr int kBandRows = 16;
  constexpr int kMaxLanes = 16;  // floats in the widest target's vector (AVX-512)
  constexpr std::size_t kPlanes = 11;  // the last two are the guide's: none when the values are their own guide
  const std::size_t planes_used = in.guide ? kPlanes : kPlanes - 2;
  const std::ptrdiff_t stride = w + 2 * r + kMaxLanes;
  tbb::enumerable_thread_specific<std::vector<float>> scratch, row_scratch;
  tbb::parallel_for(tbb::blocked_range<int>(0, (h + kBandRows - 1) / kBandRows, 1), [&](const tbb::blocked_range<int>& bands) {
    // The weights of far-apart neighbours underflow into denormals: flushed on every thread alike,
    // whatever mode the pool thread was left in, so the result is the same at any thread count.
    const detail::FlushDenormalsScope ftz;
    std::vector<float>& planes = scratch.local();
    std::vector<float>& row_out = row_scratch.local();  // a row's value and variance, for the slots
    for (int band = bands.begin(); band < bands.end(); ++band) {
      const int y0 = band * kBandRows, rows = std::min(kBandRows, h - y0);
      const auto plane_size = static_cast<std::size_t>((rows + 2 * r) * stride);
      planes.assign(planes_used * plane_size, 0.0f);
      float* p[kPlanes] = {};
      for (std::size_t k = 0; k < planes_used; ++k) p[k] = planes.data() + k * plane_size;
      std::fill_n(p[0], plane_size, std::numeric_limits<float>::quiet_NaN());
      for (int y = std::max(0, y0 - r); y < std::min(h, y0 + rows + r); ++y) {
        const std::ptrdiff_t base = (y - y0 + r) * stride + r;
        std::size_t slot = guides.row_slot(y);  // the guides' slot of the row's next covered texel
        for (int x = 0; x < w; ++x) {
          const std::size_t t = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
          const std::size_t s = slot;
          slot += cov.mask.data()[t];
          if (!valid.data()[t]) continue;
          const std::ptrdiff_t e = base + x;
          const Vec3 pos = guides.position[s], nor = guides.normal[s];
          p[0][e] = pos.x, p[1][e] = pos.y, p[2][e] = pos.z, p[3][e] = nor.x, p[4][e] = nor.y, p[5][e] = nor.z;
          p[6][e] = in.value.data()[t], p[7][e] = in.variance[s];
          if (in.guide) p[9][e] = (*in.guide)[s], p[10][e] = (*in.guide_variance)[s];
          const float texel_area = cov.uv_area[t] > 0 ? cov.world_area[t] / cov.uv_area[t] : 0.0f;  // h_c^2
          p[8][e] = texel_area > 0 ? texel_area : 0.0f;
        }
      }
      const detail::DenoiseBand b{.px = p[0], .py = p[1], .pz = p[2], .nx = p[3], .ny = p[4], .nz = p[5], .value = p[6], .variance = p[7],
                                  .guide = in.guide ? p[9] : p[6], .guide_variance = in.guide ? p[10] : p[7], .area = p[8],
                                  .stride = stride, .width = w, .radius = r,
                                  .gauss = gauss.data(), .gate = gate.data(), .plane_tolerance2 = kPlaneTolerance * kPlaneTolerance,
                                  .range_scale = 1.0f / (in.range_tolerance * in.range_tolerance), .variance_floor = kVarianceFloor,
                                  .slope_ridge = kSlopeRidge};
      for (int row = 0; row < rows; ++row) {
        if (out.map) {
          detail::denoise_row(b, row, &(*out.map)(0, y0 + row), nullptr);
          continue;
        }
        row_out.resize(2 * static_cast<std::size_t>(w));
        float* value = row_out.data();
        float* variance = value + w;
        const std::size_t first = guides.row_slot(y0 + row);
        std::size_t slot = first;
        for (int x = 0; x < w; ++x)
          if (cov.mask(x, y0 + row)) value[x] = in.value(x, y0 + row), variance[x] = in.variance[slot++];
        detail::denoise_row(b, row, value, variance);
        slot = first;
        for (int x = 0; x < w; ++x)
          if (cov.mask(x, y0 + row)) (*out.value)[slot] = value[x], (*out.variance)[slot] = variance[x], ++slot;
      }
    }
  });
}

}  // namespace

TexelGuides::TexelGuides(const Image<std::uint8_t>& covered)
    : width_(covered.width()), chunks_((static_cast<std::size_t>(covered.width()) + 63) / 64) {
  const std::size_t n = chunks_ * static_cast<std::size_t>(covered.height());
  chunk_bits_.assign(n, 0);
  chunk_first_.resize(n);
  std::size_t count = 0;
  for (int y = 0; y < covered.height(); ++y)
    for (std::size_t c = 0; c < chunks_; ++c) {
      const std::size_t k = static_cast<std::size_t>(y) * chunks_ + c;
      chunk_first_[k] = static_cast<std::uint32_t>(count);
      for (int x = static_cast<int>(64 * c); x < std::min(covered.width(), static_cast<int>(64 * c + 64)); ++x)
        if (covered(x, y)) chunk_bits_[k] |= std::uint64_t{1} << (x % 64), ++count;
    }
  position.assign(count, Vec3{0, 0, 0});
  normal.assign(count, Vec3{0, 0, 1});
  variance.assign(count, 0.0f);
}

void denoise_map(Image<float>& visibility, const Image<std::uint8_t>& valid, const TexelCoverage& cov, const TexelGuides& guides, float sigma) {
  AO_ASSERT(guides.position.size() == cov.covered_texels);  // made for cov.mask
  const Image<float> raw = visibility;
  // Pass 1, the guide: the raw values compared with each other, and the variance of each result,
  // per guide slot.
  std::vector<float> guide(guides.variance.size()), guide_variance(guides.variance.size());
  filter_pass({raw, guides.variance, nullptr, nullptr, kGuideSigma, kGuideRangeTolerance}, valid, cov, guides,
              {.value = &guide, .variance = &guide_variance});
  // Pass 2: the raw values again, weighted by how far apart the guide puts them.
  filter_pass({raw, guides.variance, &guide, &guide_variance, sigma, kRangeTolerance}, valid, cov, guides, {.map = &visibility});
}

}  // namespace ao
