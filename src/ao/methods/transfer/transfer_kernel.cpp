// SPDX-License-Identifier: Apache-2.0
// Ambient transfer's kernels (AT eq. 6, 8-9 and sec. 4 on the depth buffer; transfer_kernel_internal.h
// states what they compute), compiled once per SIMD target: the rays' nearest occluders and eq. 9's
// sums across a row's covered pixels, and the last pass that interleaves the filtered planes.
// Multiply-adds are written out (MulAdd) in the order the scalar reading of the equations gives,
// compiled without contraction, so targets with FMA agree bit for bit.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/methods/transfer/transfer_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <algorithm>

#include "ao/core/color_shared.h"

#include <hwy/highway.h>

#include "ao/methods/transfer/transfer_kernel_internal.h"
#include "ao/methods/screen_space_vec_internal.h"
#include "ao/simd/vec_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

using namespace screen_space;  // NOLINT(google-build-using-namespace): the shared per-target vocabulary

constexpr std::uint32_t kPaletteMask = 0x1F;  // a palette index's bits in a packed depth word

namespace {

// An RGB value per blocked lane (a~, or Ld~): with a palette `id` holds palette indices and the
// exact R, G, B planes of its 32 entries are looked up; else `id` holds pixels and the RGB image is
// read at them (free rays read nothing where the target has masked gathers).
HWY_INLINE void blocked_rgb(const float* palette, VI id, MF blocked, const float* image, VF& r, VF& g, VF& b) {
  if (palette) {
    r = lookup32(palette, id), g = lookup32(palette + 32, id), b = lookup32(palette + 64, id);
  } else {
    const VI a = hn::Mul(id, hn::Set(DI(), 3));
    r = gather_where(blocked, image, a), g = gather_where(blocked, image + 1, a), b = gather_where(blocked, image + 2, a);
  }
}

// Ray i of a vector of entries (sec. 4): whether any of its m test points is occluded (`blocked`),
// and the nearest occluded one's palette index (with `in.packed`) or pixel (`at`). Steps run from
// the far end inwards, each occluded one overwriting `at`.
template <bool kTwoLayers>
HWY_INLINE void nearest_occluder(const Entries& e, const Plane& pl, const StepOffsets& offsets, int i, int m, VF far, const TransferInputs& in,
                                 VI& at, MF& blocked) {
  const DF d;
  const DI di;
  const DU du;
  const VF zero = hn::Zero(d), minus_bias = hn::Neg(e.bias), exactness = hn::Set(d, 0x1p-16f);
  const VU palette_mask = hn::Set(du, kPaletteMask);
  at = hn::Zero(di);
  blocked = hn::MaskFromVec(zero);
  for (int j = m; j >= 1; --j) {
    const float* o = offsets.at(i, j);
    VF qx, qy, qz;
    e.point(o[0], o[1], o[2], qx, qy, qz);
    const VI pixel = pl.pixel(qx, qy, qz);
    const MF valid = hn::Lt(qz, zero);  // only points behind the camera are free
    VF dist;  // z* - depth(p)
    VF z1;    // z*, with the packed words within the exactness margin below (used for a front face's solid end)
    VI id = pixel;
    if (in.packed) {
      // One gather brings z* and the pixel's palette index. z* with its low mantissa bits cleared
      // is within 2^-18 of the true depth (relative); only when a comparison below is closer than
      // 2^-16 of the magnitudes involved can it differ, and then the true depth is gathered for
      // those lanes: the tests stay exact.
      const VU bits = gather_where(hn::RebindMask(du, valid), in.packed, pixel);
      const VF z_near = hn::BitCast(d, hn::AndNot(palette_mask, bits));
      dist = hn::Add(z_near, qz);
      const VF margin = hn::Mul(hn::Add(z_near, hn::Abs(qz)), exactness);
      MF close = hn::And(valid, hn::Or(hn::Lt(hn::Abs(hn::Sub(dist, minus_bias)), margin), hn::Lt(hn::Abs(hn::Sub(dist, far)), margin)));
      if constexpr (kTwoLayers) {
        // A front face's solid ends at z* + separation: that comparison is made exact the same way.
        const VF end = hn::Add(z_near, pl.separation);
        close = hn::Or(close, hn::And(valid, hn::Lt(hn::Abs(hn::Add(end, qz)), hn::Mul(hn::Add(end, hn::Abs(qz)), exactness))));
      }
      z1 = z_near;
      if (!hn::AllFalse(d, close)) {
        z1 = hn::IfThenElse(close, gather_where(close, pl.depth, pixel), z_near);
        dist = hn::IfThenElse(close, hn::Add(z1, qz), dist);
      }
      id = hn::BitCast(di, hn::And(bits, palette_mask));
    } else {
      z1 = gather_where(valid, pl.depth, pixel);
      dist = hn::Add(z1, qz);
    }
    // AT 4.3: occluded only when the surface in front is less than R in front; with a second layer
    // also inside the solid behind the surface, and between a closed solid's front and its back
    // face however far in front the front is (depth_layers.h).
    const MF behind = hn::And(valid, hn::Lt(dist, minus_bias));
    MF occluded = hn::And(behind, hn::Gt(dist, far));
    if constexpr (kTwoLayers) {
      const VF s2 = gather_where(behind, pl.second, pixel);
      occluded = hn::And(occluded, pl.in_solid(hn::Neg(qz), z1, s2, occluded, pixel, {e.px, e.py, e.pz}, {qx, qy, qz}, e.bias));
      occluded = hn::Or(occluded, hn::And(behind, Plane::inside_closed(hn::Neg(qz), s2)));
    }
    at = hn::IfThenElse(hn::RebindMask(di, occluded), id, at);
    blocked = hn::Or(blocked, occluded);
  }
}

// A vector of entries' sums over their rays: sum I, sum (1 - I) a~ and (radiance mode) sum (1 - I) Ld~.
struct TransferSums {
  VF open, lr, lg, lb, gr, gg, gb;
};

// Eq. 9, and O = sum I / n (eq. 5), stored and copied out to the entries k0.. of `row` (cheaper
// than a scatter, which is microcoded on current cores).
template <bool kDirect>
HWY_INLINE void store_transfer(const TransferSums& t, float n, const TransferInputs& in, const CoveredPixels& row, int k0, std::size_t row_base,
                               const TransferOutputs& out) {
  const DF d;
  const int lanes = static_cast<int>(hn::Lanes(d));
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f), nv = hn::Set(d, n), scale = hn::Set(d, in.albedo_scale);
  HWY_ALIGN float wr[kMaxLanes], wg[kMaxLanes], wb[kMaxLanes], wo[kMaxLanes];
  if constexpr (kDirect) {
    // (sum I + scale sum (1 - I) Ld~) / (n - scale sum (1 - I) a~), 0 unless both are > 0, not
    // clamped: lit occluders can send more than the sky would.
    const auto ratio = [&](VF lost, VF gain) {
      const VF num = hn::MulAdd(scale, gain, t.open), den = hn::NegMulAdd(scale, lost, nv);
      return hn::IfThenElseZero(hn::And(hn::Gt(num, zero), hn::Gt(den, zero)), hn::Div(num, den));
    };
    hn::Store(ratio(t.lr, t.gr), d, wr), hn::Store(ratio(t.lg, t.gg), d, wg), hn::Store(ratio(t.lb, t.gb), d, wb);
  } else {
    // The denominator is >= sum I since a~ <= 1; with no open ray at all W = 0.
    const MF lit = hn::Gt(t.open, zero);
    const auto ratio = [&](VF lost) { return hn::IfThenElseZero(lit, hn::Min(hn::Div(t.open, hn::NegMulAdd(scale, lost, nv)), one)); };
    hn::Store(ratio(t.lr), d, wr), hn::Store(ratio(t.lg), d, wg), hn::Store(ratio(t.lb), d, wb);
  }
  hn::Store(hn::Div(t.open, nv), d, wo);
  for (int k = 0; k < std::min(lanes, row.count - k0); ++k) {
    const std::size_t at_pixel = row_base + static_cast<std::size_t>(row.index[static_cast<std::size_t>(k0 + k)]);
    if (out.rgb) {  // the final images directly: W interleaved, its luminance in out.r
      out.rgb[at_pixel] = Vec3{wr[k], wg[k], wb[k]}, out.r[at_pixel] = shared::luminance(wr[k], wg[k], wb[k]), out.o[at_pixel] = wo[k];
    } else {
      out.r[at_pixel] = wr[k], out.g[at_pixel] = wg[k], out.b[at_pixel] = wb[k], out.o[at_pixel] = wo[k];
    }
  }
}

}  // namespace

template <bool kDirect, bool kTwoLayers>
void TransferRaysImpl(const CoveredPixels& row, const DepthPlane& plane, const TestPoints& s, int m, float far_limit, const TransferInputs& in,
                      std::size_t row_base, const TransferOutputs& out) {
  const DF d;
  const Plane pl(plane);
  const StepOffsets offsets(s, m);
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f), far = hn::Set(d, far_limit);
  for (int k0 = 0; k0 < row.count; k0 += static_cast<int>(hn::Lanes(d))) {
    const Entries e(row, k0);
    TransferSums t{zero, zero, zero, zero, zero, zero, zero};
    for (int i = 0; i < s.n; ++i) {
      VI at;
      MF blocked;
      nearest_occluder<kTwoLayers>(e, pl, offsets, i, m, far, in, at, blocked);
      t.open = hn::IfThenElse(blocked, t.open, hn::Add(t.open, one));
      VF ar, ag, ab;
      blocked_rgb(in.packed ? in.palette : nullptr, at, blocked, in.albedo, ar, ag, ab);
      // (1 - I) a~ of eq. 9's denominator.
      t.lr = add_where(blocked, t.lr, ar), t.lg = add_where(blocked, t.lg, ag), t.lb = add_where(blocked, t.lb, ab);
      if constexpr (kDirect) {
        // (1 - I) Ld~ in the numerator of eq. 9' (docs/methods/transfer.md), at the same occluder pixel.
        VF dr, dg, db;
        blocked_rgb(nullptr, at, blocked, in.direct, dr, dg, db);
        t.gr = add_where(blocked, t.gr, dr), t.gg = add_where(blocked, t.gg, dg), t.gb = add_where(blocked, t.gb, db);
      }
    }
    store_transfer<kDirect>(t, static_cast<float>(s.n), in, row, k0, row_base, out);
  }
}

void TransferRays(const CoveredPixels& row, const DepthPlane& plane, const TestPoints& s, int m, float far_limit, const TransferInputs& in,
                  std::size_t row_base, const TransferOutputs& out) {
  const bool two = plane.second != nullptr;
  if (in.direct)
    two ? TransferRaysImpl<true, true>(row, plane, s, m, far_limit, in, row_base, out)
        : TransferRaysImpl<true, false>(row, plane, s, m, far_limit, in, row_base, out);
  else
    two ? TransferRaysImpl<false, true>(row, plane, s, m, far_limit, in, row_base, out)
        : TransferRaysImpl<false, false>(row, plane, s, m, far_limit, in, row_base, out);
}

void InterleaveTransfer(const float* r, const float* g, const float* b, std::size_t n, Vec3* rgb, float* lum) {
  const DF d;
  const std::size_t lanes = hn::Lanes(d);
  const VF kr = hn::Set(d, shared::kLuminanceR), kg = hn::Set(d, shared::kLuminanceG), kb = hn::Set(d, shared::kLuminanceB);
  float* out = &rgb->x;  // Vec3 is three packed floats
  std::size_t k = 0;
  for (; k + lanes <= n; k += lanes) {
    const VF vr = hn::LoadU(d, r + k), vg = hn::LoadU(d, g + k), vb = hn::LoadU(d, b + k);
    hn::StoreInterleaved3(vr, vg, vb, d, out + 3 * k);
    // shared::luminance's products and sums in its order (W's Rec. 709 luminance, the method's
    // scalar visibility): the same bits as the scalar tail.
    hn::StoreU(hn::Add(hn::Add(hn::Mul(kr, vr), hn::Mul(kg, vg)), hn::Mul(kb, vb)), d, lum + k);
  }
  for (; k < n; ++k) {
    const float vr = r[k], vg = g[k], vb = b[k];
    rgb[k] = Vec3{vr, vg, vb};
    lum[k] = shared::luminance(vr, vg, vb);
  }
}

}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ao::simd {

HWY_EXPORT(TransferRays);
HWY_EXPORT(InterleaveTransfer);

void transfer_rays(const CoveredPixels& row, const DepthPlane& plane, const TestPoints& samples, int m, float far_limit,
                   const TransferInputs& in, std::size_t row_base, const TransferOutputs& out) {
  HWY_DYNAMIC_DISPATCH(TransferRays)(row, plane, samples, m, far_limit, in, row_base, out);
}

void interleave_transfer(const float* r, const float* g, const float* b, std::size_t n, Vec3* rgb, float* lum) {
  HWY_DYNAMIC_DISPATCH(InterleaveTransfer)(r, g, b, n, rgb, lum);
}

}  // namespace ao::simd
#endif
