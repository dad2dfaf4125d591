// SPDX-License-Identifier: Apache-2.0
// Kernels of the 4x4 depth-aware box filter and the cross-bilateral filter (filters_internal.h
// states what they compute), compiled once per SIMD target. The box filter only adds and divides,
// so every target gives the same bits; the bilateral filter's multiply-adds are written out
// (MulAdd) and this file is compiled without contraction, so targets with FMA agree bit for bit.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/methods/filters/filters_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <hwy/highway.h>

#include "ao/core/math.h"
#include "ao/methods/filters/filters_kernel_internal.h"
#include "ao/simd/vec_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

namespace {

constexpr int kMaxChannels = 4;
constexpr int kMaxTaps = 63;  // kMaxBilateralTaps

// Lane l of an RGB vector k (k = 0, 1, 2) of a block of Lanes() pixels belongs to pixel (k Lanes() + l) / 3.
constexpr std::array<std::int32_t, 3 * kMaxLanes> kRgbPixel = [] {
  std::array<std::int32_t, 3 * kMaxLanes> t{};
  for (int l = 0; l < 3 * kMaxLanes; ++l) t[static_cast<std::size_t>(l)] = l / 3;
  return t;
}();

// The box filter's vectors: at most 8 floats (256 bits). Its taps are loads at offsets -2..+1 of
// the pixel, so most are unaligned; a 512-bit one always spans two cache lines, a 256-bit one half
// the time (measured: AVX-512 vectors made the filter about 10% slower).
using DB = hn::CappedTag<float, 8>;
using VB = hn::Vec<DB>;

// A pixel's value or mask (as all-ones bits) spread to its S lanes: S vectors.
using IndicesB = decltype(hn::IndicesFromVec(DB(), hn::Zero(hn::RebindToSigned<DB>())));

// The permutations that spread a block's pixels to their RGB lanes, made once per call.
struct RgbSpread {
  IndicesB k[3];
  RgbSpread() {
    const DB d;
    const hn::RebindToSigned<DB> di;
    const int n = static_cast<int>(hn::Lanes(d));
    for (int j = 0; j < 3; ++j) k[j] = hn::IndicesFromVec(d, hn::LoadU(di, kRgbPixel.data() + j * n));
  }
};

template <int S>
HWY_INLINE std::array<VB, S> spread(const RgbSpread& rgb, VB v) {
  if constexpr (S == 1) {
    (void)rgb;
    return {v};
  } else {
    static_assert(S == 3);
    return {hn::TableLookupLanes(v, rgb.k[0]), hn::TableLookupLanes(v, rgb.k[1]), hn::TableLookupLanes(v, rgb.k[2])};
  }
}

// V vectors of pixels from p of row y (taps dx = -2..+1 all inside the row): the depth test is
// made once per pixel and shared by the N channels; for RGB (S = 3) its mask is spread to the
// pixel's 3 lanes. The count and sums stay in registers through the 16 taps (V blocks give V
// independent chains of additions).
template <int S, int N, int V>
HWY_INLINE void box_block(const BoxFilterImage& im, const RgbSpread& rgb, const float* centre, int y, int p, int dy_lo, int dy_hi, float limit) {
  const DB d;
  const int n = static_cast<int>(hn::Lanes(d));
  const std::size_t lanes = static_cast<std::size_t>(S) * static_cast<std::size_t>(im.width);
  const VB lim = hn::Set(d, limit), one = hn::Set(d, 1.0f), zero = hn::Zero(d);
  VB dc[V], count[V], sum[V][N * S];
  for (int u = 0; u < V; ++u) {
    dc[u] = hn::LoadU(d, centre + p + n * u), count[u] = zero;
    for (int k = 0; k < N * S; ++k) sum[u][k] = zero;
  }
  for (int dy = dy_lo; dy <= dy_hi; ++dy) {
    const float* dn = im.depth + static_cast<std::size_t>(y + dy) * im.width + p;
    const std::size_t nrow = static_cast<std::size_t>(y + dy) * lanes + static_cast<std::size_t>(S) * p;
    HWY_UNROLL(4)
    for (int dx = -2; dx <= 1; ++dx) {
      HWY_UNROLL(2)
      for (int u = 0; u < V; ++u) {
        const hn::Mask<DB> m = hn::Le(hn::Abs(hn::Sub(hn::LoadU(d, dn + dx + n * u), dc[u])), lim);
        count[u] = hn::Add(count[u], hn::IfThenElseZero(m, one));
        const std::array<VB, S> e = spread<S>(rgb, hn::VecFromMask(d, m));
        HWY_UNROLL(4)
        for (int c = 0; c < N; ++c) {
          const float* v = im.src[c] + nrow + S * (dx + n * u);
          HWY_UNROLL(3)
          for (int k = 0; k < S; ++k) sum[u][c * S + k] = hn::Add(sum[u][c * S + k], hn::And(e[static_cast<std::size_t>(k)], hn::LoadU(d, v + n * k)));
        }
      }
    }
  }
  const std::size_t row = static_cast<std::size_t>(y) * lanes;
  for (int u = 0; u < V; ++u) {
    const std::array<VB, S> q = spread<S>(rgb, count[u]);
    for (int k = 0; k < S; ++k) {
      const VB qk = q[static_cast<std::size_t>(k)];
      const hn::Mask<DB> some = hn::Gt(qk, zero);  // else keep the value (uncovered, or no tap)
      for (int c = 0; c < N; ++c) {
        const std::size_t at = row + static_cast<std::size_t>(S) * (p + n * u) + static_cast<std::size_t>(n * k);
        hn::StoreU(hn::IfThenElse(some, hn::Div(sum[u][c * S + k], qk), hn::LoadU(d, im.src[c] + at)), d, im.dst[c] + at);
      }
    }
  }
}

template <int S, int N>
void BoxRows(const BoxFilterImage& im, float limit, int y0, int y1) {
  const DB d;
  const int n = static_cast<int>(hn::Lanes(d));
  const int w = im.width, h = im.height, lanes = S * w, channels = N;
  const float* depth = im.depth;
  auto depth_row = [&](int yy) { return depth + static_cast<std::size_t>(yy) * w; };
  // Centre depths, NaN on uncovered pixels: no tap passes, the count stays 0 and the value is kept.
  AlignedVector<float> centre(static_cast<std::size_t>(w));
  const RgbSpread rgb;
  for (int y = y0; y < y1; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * lanes;
    const float* dcy = depth_row(y);
    const std::uint32_t* cov = im.object_id + static_cast<std::size_t>(y) * w;
    for (int x = 0; x < w; ++x) centre[static_cast<std::size_t>(x)] = cov[x] ? dcy[x] : std::numeric_limits<float>::quiet_NaN();
    const int dy_lo = std::max(-2, -y), dy_hi = std::min(1, h - 1 - y);
    // Pixels whose taps dx = -2..+1 all lie inside the row: two vectors at a time, then one.
    int p = 2;
    for (; p + 2 * n <= w - 1; p += 2 * n) box_block<S, N, 2>(im, rgb, centre.data(), y, p, dy_lo, dy_hi, limit);
    for (; p + n <= w - 1; p += n) box_block<S, N, 1>(im, rgb, centre.data(), y, p, dy_lo, dy_hi, limit);
    // The rest one lane at a time, same tap order.
    const int l = S * p, vlo = 2 * S;
    auto scalar = [&](int l0, int l1) {
      for (int q = l0; q < l1; ++q) {
        const int x = q / S;
        const float dc = centre[static_cast<std::size_t>(x)];
        float count = 0;
        std::array<float, kMaxChannels> s{};
        for (int dy = dy_lo; dy <= dy_hi; ++dy) {
          const float* dn = depth_row(y + dy);
          const std::size_t nrow = static_cast<std::size_t>(y + dy) * lanes;
          for (int dx = std::max(-2, -x); dx <= std::min(1, w - 1 - x); ++dx) {
            const int t = q + S * dx;
            const bool use = std::abs(dn[x + dx] - dc) <= limit;
            count += use ? 1.0f : 0.0f;
            for (int c = 0; c < channels; ++c) s[static_cast<std::size_t>(c)] += use ? im.src[c][nrow + t] : 0.0f;
          }
        }
        for (int c = 0; c < channels; ++c) {
          const float in = im.src[c][row + q];
          im.dst[c][row + q] = count > 0 ? s[static_cast<std::size_t>(c)] / count : in;
        }
      }
    };
    scalar(0, std::min(vlo, lanes));
    scalar(std::max(l, std::min(vlo, lanes)), lanes);
  }
}

// V vectors of pixels: the centres from entry k0, tap j's data from tt[j] + kt (tt[j][0] without
// per_pixel_t), td[j] + kt, tv[j] + kt, the input from `in`; the results to `out`. The taps' sums
// stay in registers, in tap order (V vectors: 2V independent chains of additions).
template <int V>
HWY_INLINE void bilateral_vectors(const BilateralCentres& ce, int k0, int taps, const float* sp, const float* const* tt, bool per_pixel_t,
                                  const float* const* td, const float* const* tv, int kt, const float* in, float* out) {
  const DF d;
  const int n = static_cast<int>(hn::Lanes(d));
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f);
  VF a[V], b[V], c[V], sum_w[V], sum_v[V];
  for (int u = 0; u < V; ++u) {
    a[u] = hn::Load(d, ce.a.data() + k0 + n * u), b[u] = hn::Load(d, ce.b.data() + k0 + n * u), c[u] = hn::Load(d, ce.c.data() + k0 + n * u);
    sum_w[u] = zero, sum_v[u] = zero;
  }
  for (int j = 0; j < taps; ++j) {
    const VF spatial = hn::Set(d, sp[j]);
    for (int u = 0; u < V; ++u) {
      const VF t = per_pixel_t ? hn::LoadU(d, tt[j] + kt + n * u) : hn::Set(d, tt[j][0]);
      const VF depth = hn::LoadU(d, td[j] + kt + n * u);
      // x/2 = d (a t + b) - c; K = max(0, 1 - (x/2)^2)^2. Background taps (d = +inf): x/2 is +-inf
      // or NaN, so u = 0 and w = 0 (the comparison is false for NaN).
      const VF half_x = hn::MulSub(depth, hn::MulAdd(a[u], t, b[u]), c[u]);
      const VF k = hn::NegMulAdd(half_x, half_x, one);
      const VF kc = hn::IfThenElseZero(hn::Gt(k, zero), k);
      const VF w = hn::Mul(spatial, hn::Mul(kc, kc));
      sum_w[u] = hn::Add(sum_w[u], w);
      sum_v[u] = hn::MulAdd(w, hn::LoadU(d, tv[j] + kt + n * u), sum_v[u]);
    }
  }
  // The centre tap has weight spatial(0) * 1 > 0 on covered pixels, so sum_w > 0 there.
  for (int u = 0; u < V; ++u)
    hn::StoreU(hn::IfThenElse(hn::Gt(hn::Load(d, ce.cov.data() + k0 + n * u), zero), hn::Div(sum_v[u], sum_w[u]), hn::LoadU(d, in + n * u)), d,
               out + n * u);
}

}  // namespace

void BoxFilterRows(const BoxFilterImage& image, float depth_limit, int y0, int y1) {
  if (image.stride == 3) return BoxRows<3, 1>(image, depth_limit, y0, y1);  // RGB: one image
  switch (image.channels) {
    case 1: return BoxRows<1, 1>(image, depth_limit, y0, y1);
    case 2: return BoxRows<1, 2>(image, depth_limit, y0, y1);
    case 3: return BoxRows<1, 3>(image, depth_limit, y0, y1);
    default: return BoxRows<1, 4>(image, depth_limit, y0, y1);
  }
}

void BilateralCentresRow(BilateralCentres& ce, const float* normal, const float* depth, const std::uint32_t* object_id, int x0, int count,
                         float ray_ax, float ray_bx, float ry, float plane_sigma, bool vertical) {
  const DF d;
  const DU du;
  const int n = static_cast<int>(hn::Lanes(d));
  const std::size_t cap = static_cast<std::size_t>(padded(count));
  for (AlignedVector<float>* v : {&ce.a, &ce.b, &ce.c, &ce.cov}) v->resize(cap);
  const VF half = hn::Set(d, 0.5f), sigma = hn::Set(d, plane_sigma), ax = hn::Set(d, ray_ax), bx = hn::Set(d, ray_bx),
           vry = hn::Set(d, ry);
  // The last partial vector reads copies padded with uncovered pixels, so no read passes the image.
  HWY_ALIGN float tail_n[3 * kMaxLanes], tail_d[kMaxLanes];
  HWY_ALIGN std::uint32_t tail_id[kMaxLanes];
  const VI lane = hn::Iota(DI(), 0);  // made once: Highway builds it through memory
  for (int k0 = 0; k0 < count; k0 += n) {
    const float* nn = normal + 3 * static_cast<std::size_t>(k0);
    const float* dd = depth + k0;
    const std::uint32_t* id = object_id + k0;
    if (k0 + n > count) {
      const int rest = count - k0;
      for (int k = 0; k < n; ++k) {
        const bool real = k < rest;
        for (int c = 0; c < 3; ++c) tail_n[3 * k + c] = real ? nn[3 * k + c] : 0.0f;
        tail_d[k] = real ? dd[k] : 1.0f, tail_id[k] = real ? id[k] : 0u;
      }
      nn = tail_n, dd = tail_d, id = tail_id;
    }
    VF nx, ny, nz;
    hn::LoadInterleaved3(d, nn, nx, ny, nz);
    const MF covered = hn::RebindMask(d, hn::Not(hn::Eq(hn::LoadU(du, id), hn::Zero(du))));
    const VF depth_v = hn::IfThenElseZero(covered, hn::LoadU(d, dd));
    const VF px = hn::Add(hn::ConvertTo(d, hn::Add(lane, hn::Set(DI(), x0 + k0))), half);
    const VF rx = hn::MulAdd(ax, px, bx);
    // Background: scale 0 (and cov 0), so its result is never used.
    const VF half_s = hn::IfThenElseZero(covered, hn::Div(half, hn::Mul(sigma, depth_v)));
    hn::Store(hn::Mul(vertical ? ny : nx, half_s), d, ce.a.data() + k0);
    hn::Store(hn::Mul(vertical ? hn::MulSub(nx, rx, nz) : hn::MulSub(ny, vry, nz), half_s), d, ce.b.data() + k0);
    hn::Store(hn::Mul(hn::Mul(depth_v, hn::Sub(hn::MulAdd(ny, vry, hn::Mul(nx, rx)), nz)), half_s), d, ce.c.data() + k0);
    hn::Store(hn::IfThenElseZero(covered, hn::Set(d, 1.0f)), d, ce.cov.data() + k0);
  }
}

void BilateralTaps(const BilateralCentres& ce, int count, int taps, const float* spatial, const float* const* tt, bool per_pixel_t,
                   const float* const* td, const float* const* tv, const float* in, float* out) {
  const DF d;
  const int n = static_cast<int>(hn::Lanes(d));
  int k0 = 0;
  for (; k0 + 2 * n <= count; k0 += 2 * n) bilateral_vectors<2>(ce, k0, taps, spatial, tt, per_pixel_t, td, tv, k0, in + k0, out + k0);
  for (; k0 + n <= count; k0 += n) bilateral_vectors<1>(ce, k0, taps, spatial, tt, per_pixel_t, td, tv, k0, in + k0, out + k0);
  if (k0 == count) return;
  // The last partial vector: its taps' rows copied into buffers padded with background (depth
  // +inf: weight 0), so no read passes the image and the arithmetic is the vector's.
  const int rest = count - k0;  // in [1, n)
  HWY_ALIGN float bt[kMaxTaps][kMaxLanes], bd[kMaxTaps][kMaxLanes], bv[kMaxTaps][kMaxLanes], bin[kMaxLanes], bout[kMaxLanes];
  std::array<const float*, kMaxTaps> ptt, ptd, ptv;
  for (int j = 0; j < taps; ++j) {
    for (int k = 0; k < n; ++k) {
      const bool real = k < rest;
      bt[j][k] = per_pixel_t ? (real ? tt[j][k0 + k] : 0.0f) : tt[j][0];
      bd[j][k] = real ? td[j][k0 + k] : kInfinity;
      bv[j][k] = real ? tv[j][k0 + k] : 0.0f;
    }
    ptt[static_cast<std::size_t>(j)] = bt[j], ptd[static_cast<std::size_t>(j)] = bd[j], ptv[static_cast<std::size_t>(j)] = bv[j];
  }
  for (int k = 0; k < n; ++k) bin[k] = k < rest ? in[k0 + k] : 0.0f;
  // The centres are padded: their arrays hold whole vectors, the part past `count` unused.
  bilateral_vectors<1>(ce, k0, taps, spatial, ptt.data(), per_pixel_t, ptd.data(), ptv.data(), 0, bin, bout);
  for (int k = 0; k < rest; ++k) out[k0 + k] = bout[k];
}

}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ao::simd {

HWY_EXPORT(BoxFilterRows);
HWY_EXPORT(BilateralCentresRow);
HWY_EXPORT(BilateralTaps);

void box_filter_rows(const BoxFilterImage& image, float depth_limit, int y0, int y1) {
  HWY_DYNAMIC_DISPATCH(BoxFilterRows)(image, depth_limit, y0, y1);
}

void bilateral_centres(BilateralCentres& centres, const float* normal, const float* depth, const std::uint32_t* object_id, int x0, int count,
                       float ray_ax, float ray_bx, float ry, float plane_sigma, bool vertical) {
  HWY_DYNAMIC_DISPATCH(BilateralCentresRow)(centres, normal, depth, object_id, x0, count, ray_ax, ray_bx, ry, plane_sigma, vertical);
}

void bilateral_taps(const BilateralCentres& centres, int count, int taps, const float* spatial, const float* const* tt, bool per_pixel_t,
                    const float* const* td, const float* const* tv, const float* in, float* out) {
  HWY_DYNAMIC_DISPATCH(BilateralTaps)(centres, count, taps, spatial, tt, per_pixel_t, td, tv, in, out);
}

}  // namespace ao::simd
#endif
