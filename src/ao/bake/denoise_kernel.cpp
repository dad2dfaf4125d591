// SPDX-License-Identifier: Apache-2.0
// The bake filter's row loop (bake/denoise_internal.h), compiled once per SIMD target: a vector holds
// neighbouring texels of one row, and each tap of the window is one offset (dx, dy) for all of them,
// so every load is a contiguous run of a plane, and the tap's Gaussian, gate and offsets are scalars.
// The weights and the fit are denoise.h's; the exponential is Highway's (a polynomial after range
// reduction, within a few ulp of exp). Part of ao::ao.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/bake/denoise_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <algorithm>
#include <cstddef>

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

#include "ao/bake/denoise_internal.h"
#include "ao/simd/vec_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

// The value at the centre of the plane fitted by weighted least squares, from the window's moments
// m = (m0, mx, my, mxx, mxy, myy, s0, sx, sy) (sums of w, w dx, w dy, w dx^2, w dx dy, w dy^2, w V,
// w V dx, w V dy): the normal equations with the ridge lambda m0 on the slopes,
//   [m0 mx my; mx mxx+l mxy; my mxy myy+l] (a b_x b_y) = (s0 sx sy),
// solved for a by Cramer's rule in double. The matrix is positive definite (m0 >= 1: the centre
// weighs 1; l > 0), so its determinant is positive; the weighted mean stands in should rounding say
// otherwise.
inline float plane_at_centre(const float (&m)[9], float ridge) {
  const double m0 = m[0], mx = m[1], my = m[2], s0 = m[6], sx = m[7], sy = m[8];
  const double l = static_cast<double>(ridge) * m0;
  const double pxx = m[3] + l, pyy = m[5] + l, pxy = m[4];
  const double c00 = pxx * pyy - pxy * pxy, c01 = mx * pyy - pxy * my, c02 = mx * pxy - pxx * my;
  const double det = m0 * c00 - mx * c01 + my * c02;
  const double a = det > 0 ? (s0 * c00 - mx * (sx * pyy - pxy * sy) + my * (sx * pxy - pxx * sy)) / det : s0 / m0;
  return static_cast<float>(std::clamp(a, 0.0, 1.0));
}

template <bool kVariance>
void DenoiseRowImpl(const detail::DenoiseBand& b, int row, float* out, float* out_variance) {
  const DF d;
  const std::size_t n = hn::Lanes(d);
  const int r = b.radius, side = 2 * r + 1;
  const VF zero = hn::Zero(d), half = hn::Set(d, 0.5f), floor = hn::Set(d, b.variance_floor), range_scale = hn::Set(d, b.range_scale);
  const VF tau2 = hn::Set(d, b.plane_tolerance2), one = hn::Set(d, 1.0f);
  HWY_ALIGN float moments[10][HWY_MAX_BYTES / sizeof(float)];
  for (int x0 = 0; x0 < b.width; x0 += static_cast<int>(n)) {
    const std::ptrdiff_t c = (row + r) * b.stride + x0 + r;
    const VF area = hn::LoadU(d, b.area + c);
    const MF filtered = hn::Gt(area, zero);
    if (hn::AllFalse(d, filtered)) continue;
    const VF pcx = hn::LoadU(d, b.px + c), pcy = hn::LoadU(d, b.py + c), pcz = hn::LoadU(d, b.pz + c);
    const VF ncx = hn::LoadU(d, b.nx + c), ncy = hn::LoadU(d, b.ny + c), ncz = hn::LoadU(d, b.nz + c);
    const VF gc = hn::LoadU(d, b.guide + c), var_c = hn::LoadU(d, b.guide_variance + c);
    const VF plane_scale = hn::Div(one, hn::Mul(tau2, area));
    VF m0 = zero, mx = zero, my = zero, mxx = zero, mxy = zero, myy = zero, s0 = zero, sx = zero, sy = zero, w2v = zero;
    for (int dy = -r; dy <= r; ++dy) {
      // The row's sums of w, w dx, w dx^2, w V and w V dx; its dy enters once per row.
      VF r0 = zero, rx = zero, rxx = zero, t0 = zero, tx = zero;
      const std::ptrdiff_t q0 = c + dy * b.stride;
      const float* gauss = b.gauss + (dy + r) * side + r;
      const float* gate = b.gate + (dy + r) * side + r;
      for (int dx = -r; dx <= r; ++dx) {
        const std::ptrdiff_t q = q0 + dx;
        const VF ddx = hn::Sub(hn::LoadU(d, b.px + q), pcx), ddy = hn::Sub(hn::LoadU(d, b.py + q), pcy), ddz = hn::Sub(hn::LoadU(d, b.pz + q), pcz);
        // Far on the surface (another chart), or not a texel that takes part (NaN): no weight.
        const MF near = hn::Le(hn::Add(hn::Add(hn::Mul(ddx, ddx), hn::Mul(ddy, ddy)), hn::Mul(ddz, ddz)), hn::Mul(hn::Set(d, gate[dx]), area));
        const VF off_plane = hn::Add(hn::Add(hn::Mul(ddx, ncx), hn::Mul(ddy, ncy)), hn::Mul(ddz, ncz));
        VF cn = hn::Max(zero, hn::Add(hn::Add(hn::Mul(ncx, hn::LoadU(d, b.nx + q)), hn::Mul(ncy, hn::LoadU(d, b.ny + q))), hn::Mul(ncz, hn::LoadU(d, b.nz + q))));
        cn = hn::Mul(cn, cn), cn = hn::Mul(cn, cn), cn = hn::Mul(cn, cn);
        const VF vq = hn::LoadU(d, b.value + q), dv = hn::Sub(hn::LoadU(d, b.guide + q), gc);
        const VF var = hn::Add(hn::Add(var_c, hn::LoadU(d, b.guide_variance + q)), floor);
        const VF e = hn::Add(hn::Mul(hn::Mul(off_plane, off_plane), plane_scale), hn::Div(hn::Mul(hn::Mul(dv, dv), range_scale), var));
        const VF w = hn::IfThenElseZero(near, hn::Mul(hn::Mul(hn::Set(d, gauss[dx]), hn::Exp(d, hn::Mul(hn::Neg(half), e))), cn));
        const VF fx = hn::Set(d, static_cast<float>(dx));
        const VF wx = hn::Mul(w, fx), wv = hn::Mul(w, vq);
        r0 = hn::Add(r0, w), rx = hn::Add(rx, wx), rxx = hn::Add(rxx, hn::Mul(wx, fx));
        t0 = hn::Add(t0, wv), tx = hn::Add(tx, hn::Mul(wv, fx));
        if constexpr (kVariance) w2v = hn::Add(w2v, hn::Mul(hn::Mul(w, w), hn::LoadU(d, b.variance + q)));
      }
      const VF fy = hn::Set(d, static_cast<float>(dy));
      m0 = hn::Add(m0, r0), mx = hn::Add(mx, rx), my = hn::Add(my, hn::Mul(r0, fy));
      mxx = hn::Add(mxx, rxx), mxy = hn::Add(mxy, hn::Mul(rx, fy)), myy = hn::Add(myy, hn::Mul(hn::Mul(r0, fy), fy));
      s0 = hn::Add(s0, t0), sx = hn::Add(sx, tx), sy = hn::Add(sy, hn::Mul(t0, fy));
    }
    const VF sums[10] = {m0, mx, my, mxx, mxy, myy, s0, sx, sy, w2v};
    for (int k = 0; k < 10; ++k) hn::Store(sums[k], d, moments[k]);
    const int lanes = std::min(static_cast<int>(n), b.width - x0);
    for (int i = 0; i < lanes; ++i) {
      if (!(b.area[c + i] > 0) || !(moments[0][i] > 0)) continue;
      float m[9];
      for (int k = 0; k < 9; ++k) m[k] = moments[k][i];
      out[x0 + i] = plane_at_centre(m, b.slope_ridge);
      if constexpr (kVariance) out_variance[x0 + i] = moments[9][i] / (m[0] * m[0]);
    }
  }
}

void DenoiseRow(const detail::DenoiseBand& b, int row, float* out, float* out_variance) {
  if (out_variance)
    DenoiseRowImpl<true>(b, row, out, out_variance);
  else
    DenoiseRowImpl<false>(b, row, out, nullptr);
}

}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ao::simd {

HWY_EXPORT(DenoiseRow);

// Dispatched from the namespace of HWY_EXPORT: with a single static target (AO_NATIVE=ON)
// HWY_DYNAMIC_DISPATCH(F) is F of that target's namespace, named relative to the calling scope.
namespace {
void dispatch_denoise_row(const detail::DenoiseBand& band, int row, float* out, float* out_variance) {
  HWY_DYNAMIC_DISPATCH(DenoiseRow)(band, row, out, out_variance);
}
}  // namespace

}  // namespace ao::simd

namespace ao::detail {

void denoise_row(const DenoiseBand& band, int row, float* out, float* out_variance) { simd::dispatch_denoise_row(band, row, out, out_variance); }

}  // namespace ao::detail
#endif  // HWY_ONCE
