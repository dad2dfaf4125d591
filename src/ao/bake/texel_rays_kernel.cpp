// SPDX-License-Identifier: Apache-2.0
// The ray-traced baker's ray makers (bake/texel_rays_internal.h: make_texel_rays,
// make_hemisphere_rays), compiled once per SIMD target. make_texel_rays is written in Highway
// vectors over the 16 lanes of a batch (4, 8 or 16 floats at a time, as the target holds), with
// the scalar code's operations in its order, so a lane's bits do not depend on the target;
// make_hemisphere_rays is a scalar loop over the batch's lanes up to its count (high to low fills a
// batch with the few samples of one cage point). A portable build makes
// its rays as fast as one compiled for the CPU. Part of ao::ao (the batch and the patch belong to
// the bakers).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/bake/texel_rays_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <algorithm>
#include <cmath>

#include <hwy/highway.h>

#include "ao/bake/texel_rays_internal.h"
#include "ao/simd/vec_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

using detail::PatchPiece;
using detail::PatchTable;
using detail::TexelRayBatch;

// sin t and cos t for t in [-pi/4, pi/4], from their Taylor series to degree 9 and 10: the
// remainders, |t|^11/11! and |t|^12/12!, are below 2e-9 there, under float rounding.
inline void sincos_quarter(float t, float& s, float& c) {
  const float t2 = t * t;
  s = t * (1.0f + t2 * (-1.0f / 6 + t2 * (1.0f / 120 + t2 * (-1.0f / 5040 + t2 * (1.0f / 362880)))));
  c = 1.0f + t2 * (-1.0f / 2 + t2 * (1.0f / 24 + t2 * (-1.0f / 720 + t2 * (1.0f / 40320 + t2 * (-1.0f / 3628800)))));
}

// cosine_hemisphere: the concentric map with phi = (pi/4)(b/a) when |a| > |b|, else
// pi/2 - (pi/4)(a/b), whose cosine and sine are the sine and cosine of (pi/4)(a/b).
inline void concentric_hemisphere(float u0, float u1, float& lx, float& ly, float& lz) {
  const float ca = 2.0f * u0 - 1.0f, cb = 2.0f * u1 - 1.0f;
  const bool use_a = std::abs(ca) > std::abs(cb);
  const float rad = use_a ? ca : cb, q = use_a ? cb : ca;
  float s, c;
  sincos_quarter((kPi / 4) * (q / (rad != 0.0f ? rad : 1.0f)), s, c);  // a = b = 0: rad = 0, so (0, 0, 1)
  lx = rad * (use_a ? c : s), ly = rad * (use_a ? s : c);
  lz = std::sqrt(std::max(0.0f, 1.0f - lx * lx - ly * ly));
}

// The same arithmetic as concentric_hemisphere, lane-parallel: the operations in its order, so
// that a lane's bits are those the scalar code gives.
HWY_INLINE void concentric_hemisphere(VF u0, VF u1, VF& lx, VF& ly, VF& lz) {
  const DF d;
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f), two = hn::Set(d, 2.0f);
  const VF ca = hn::Sub(hn::Mul(two, u0), one), cb = hn::Sub(hn::Mul(two, u1), one);
  const MF use_a = hn::Gt(hn::Abs(ca), hn::Abs(cb));
  const VF rad = hn::IfThenElse(use_a, ca, cb), q = hn::IfThenElse(use_a, cb, ca);
  const VF t = hn::Mul(hn::Set(d, kPi / 4), hn::Div(q, hn::IfThenElse(hn::Ne(rad, zero), rad, one)));
  const VF t2 = hn::Mul(t, t);
  VF s = hn::Add(hn::Set(d, -1.0f / 5040), hn::Mul(t2, hn::Set(d, 1.0f / 362880)));
  s = hn::Add(hn::Set(d, 1.0f / 120), hn::Mul(t2, s));
  s = hn::Add(hn::Set(d, -1.0f / 6), hn::Mul(t2, s));
  s = hn::Mul(t, hn::Add(one, hn::Mul(t2, s)));
  VF c = hn::Add(hn::Set(d, 1.0f / 40320), hn::Mul(t2, hn::Set(d, -1.0f / 3628800)));
  c = hn::Add(hn::Set(d, -1.0f / 720), hn::Mul(t2, c));
  c = hn::Add(hn::Set(d, 1.0f / 24), hn::Mul(t2, c));
  c = hn::Add(hn::Set(d, -1.0f / 2), hn::Mul(t2, c));
  c = hn::Add(one, hn::Mul(t2, c));
  lx = hn::Mul(rad, hn::IfThenElse(use_a, c, s)), ly = hn::Mul(rad, hn::IfThenElse(use_a, s, c));
  const VF rest = hn::Sub(hn::Sub(one, hn::Mul(lx, lx)), hn::Mul(ly, ly));
  lz = hn::Sqrt(hn::IfThenElse(hn::Lt(zero, rest), rest, zero));  // std::max(0, rest)
}

// a0 w0 + a1 w1 + a2 w2 of field rows q, q + 3 and q + 6 (a corner-weighted sum), in that order.
HWY_INLINE VF corner_sum(const float (&lane)[detail::PatchTable::kFields][TexelRayBatch::kWidth], int q, int k, VF w0, VF w1, VF w2) {
  const DF d;
  return hn::Add(hn::Add(hn::Mul(hn::Load(d, lane[q] + k), w0), hn::Mul(hn::Load(d, lane[q + 3] + k), w1)), hn::Mul(hn::Load(d, lane[q + 6] + k), w2));
}

void MakeTexelRays(const std::vector<PatchPiece>& patch, const PatchTable& table, const float (&u)[4][16], int count, bool geometric,
                     TexelRayBatch& out) {
  constexpr int W = TexelRayBatch::kWidth;
  using T = PatchTable;
  const DF d;
  const DI di;
  const int lanes = static_cast<int>(hn::Lanes(d));
  // The vectors that hold the count's lanes: the rest of the batch is only marked "no ray".
  const int used = (count + lanes - 1) / lanes * lanes;
  // Per lane, the piece (sample_patch's: the first whose cumulative area exceeds u2 * total; the
  // cumulative areas are non-decreasing) and its fields, gathered from the texel's table into lane
  // rows, so that the arithmetic below reads whole vectors.
  alignas(64) float lane[T::kFields][W];
  alignas(64) float target[W];
  alignas(64) int piece[W];
  const VF total = hn::Set(d, patch.back().cdf);
  for (int k = 0; k < used; k += lanes) {
    const VF tk = hn::Mul(hn::LoadU(d, u[2] + k), total);
    VI pk = hn::Zero(di);
    for (std::size_t j = 0; j + 1 < patch.size(); ++j)
      pk = hn::Sub(pk, hn::VecFromMask(di, hn::RebindMask(di, hn::Le(hn::Set(d, patch[j].cdf), tk))));  // a true mask lane is -1
    hn::Store(tk, d, target + k);
    hn::Store(pk, di, piece + k);
  }
  if (patch.size() <= static_cast<std::size_t>(lanes)) {
    // Few pieces (the common case): a permute within one register per field.
    for (int k = 0; k < used; k += lanes) {
      const auto pk = hn::IndicesFromVec(d, hn::Load(di, piece + k));
      for (int q = 0; q < T::kFields; ++q) hn::Store(hn::TableLookupLanes(hn::Load(d, table.f[q]), pk), d, lane[q] + k);
    }
  } else if (patch.size() <= T::kMaxPieces) {
    for (int k = 0; k < used; k += lanes) {
      const VI pk = hn::Load(di, piece + k);
      for (int q = 0; q < T::kFields; ++q) hn::Store(lookup16(table.f[q], pk), d, lane[q] + k);
    }
  } else {
    for (int k = 0; k < used; ++k) {
      float v[T::kFields];
      table.piece_fields(patch, static_cast<std::size_t>(piece[k]), v);
      for (int q = 0; q < T::kFields; ++q) lane[q][k] = v[q];
    }
  }
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f), tiny = hn::Set(d, 1e-6f);
  const MF all_face = hn::RebindMask(d, hn::Ne(hn::Set(di, geometric ? 1 : 0), hn::Zero(di)));
  for (int k = used; k < W; ++k) out.valid[k] = 0;
  for (int k = 0; k < used; k += lanes) {
    // The point: corner weights (1 - r, r (1 - t), r t), r = sqrt(s), as sample_patch, s clamped to [0, 1].
    VF su = hn::Mul(hn::Sub(hn::Load(d, target + k), hn::Load(d, lane[T::kLo] + k)), hn::Load(d, lane[T::kInvSpan] + k));
    su = hn::IfThenElse(hn::Lt(su, zero), zero, su);
    su = hn::IfThenElse(hn::Lt(one, su), one, su);
    const VF r = hn::Sqrt(su), u3 = hn::LoadU(d, u[3] + k);
    const VF w0 = hn::Sub(one, r), w1 = hn::Mul(r, hn::Sub(one, u3)), w2 = hn::Mul(r, u3);
    const VF px = corner_sum(lane, T::kP, k, w0, w1, w2), py = corner_sum(lane, T::kP + 1, k, w0, w1, w2), pz = corner_sum(lane, T::kP + 2, k, w0, w1, w2);
    const VF mx = corner_sum(lane, T::kN, k, w0, w1, w2), my = corner_sum(lane, T::kN + 1, k, w0, w1, w2), mz = corner_sum(lane, T::kN + 2, k, w0, w1, w2);
    // The unit normal (PatchSample::normal: the face normal where the vertex normals cancel).
    const VF len = hn::Sqrt(hn::Add(hn::Add(hn::Mul(mx, mx), hn::Mul(my, my)), hn::Mul(mz, mz)));
    const MF face = hn::Or(all_face, hn::Not(hn::Gt(len, tiny)));
    const VF inv = hn::Div(one, hn::IfThenElse(hn::Lt(len, tiny), tiny, len));
    const VF gx = hn::Load(d, lane[T::kNg] + k), gy = hn::Load(d, lane[T::kNg + 1] + k), gz = hn::Load(d, lane[T::kNg + 2] + k);
    const VF nx = hn::IfThenElse(face, gx, hn::Mul(mx, inv)), ny = hn::IfThenElse(face, gy, hn::Mul(my, inv)), nz = hn::IfThenElse(face, gz, hn::Mul(mz, inv));
    // Frame::from_normal (Duff et al. 2017).
    const VF sign = hn::CopySign(one, nz);
    const VF fa = hn::Div(hn::Set(d, -1.0f), hn::Add(sign, nz));
    const VF fc = hn::Mul(hn::Mul(nx, ny), fa);
    const VF tx = hn::Add(one, hn::Mul(hn::Mul(hn::Mul(sign, nx), nx), fa)), ty = hn::Mul(sign, fc), tz = hn::Mul(hn::Neg(sign), nx);
    const VF bx = fc, by = hn::Add(sign, hn::Mul(hn::Mul(ny, ny), fa)), bz = hn::Neg(ny);
    VF lx, ly, lz;
    concentric_hemisphere(hn::LoadU(d, u[0] + k), hn::LoadU(d, u[1] + k), lx, ly, lz);
    const VF dx = hn::Add(hn::Add(hn::Mul(tx, lx), hn::Mul(bx, ly)), hn::Mul(nx, lz));
    const VF dy = hn::Add(hn::Add(hn::Mul(ty, lx), hn::Mul(by, ly)), hn::Mul(ny, lz));
    const VF dz = hn::Add(hn::Add(hn::Mul(tz, lx), hn::Mul(bz, ly)), hn::Mul(nz, lz));
    // Below the face: occluded by the surface itself (mu = 0), no ray.
    const MF above = hn::Gt(hn::Add(hn::Add(hn::Mul(dx, gx), hn::Mul(dy, gy)), hn::Mul(dz, gz)), zero);
    const MF live = hn::RebindMask(d, hn::Lt(hn::Iota(di, k), hn::Set(di, count)));
    hn::Store(hn::VecFromMask(di, hn::RebindMask(di, hn::And(above, live))), di, out.valid + k);
    const VF off = hn::Load(d, lane[T::kOff] + k);
    hn::Store(hn::Add(px, hn::Mul(gx, off)), d, out.ox + k);
    hn::Store(hn::Add(py, hn::Mul(gy, off)), d, out.oy + k);
    hn::Store(hn::Add(pz, hn::Mul(gz, off)), d, out.oz + k);
    hn::Store(dx, d, out.dx + k), hn::Store(dy, d, out.dy + k), hn::Store(dz, d, out.dz + k);
  }
}

void MakeHemisphereRays(Vec3 origin, Vec3 n, Vec3 ng, const float (&u)[4][16], int count, TexelRayBatch& out) {
  const Frame f = Frame::from_normal(n);
  for (int k = 0; k < count; ++k) {
    float lx, ly, lz;
    concentric_hemisphere(u[0][k], u[1][k], lx, ly, lz);
    const float dx = f.t.x * lx + f.b.x * ly + f.n.x * lz, dy = f.t.y * lx + f.b.y * ly + f.n.y * lz, dz = f.t.z * lx + f.b.z * ly + f.n.z * lz;
    out.valid[k] = dx * ng.x + dy * ng.y + dz * ng.z > 0 ? -1 : 0;
    out.ox[k] = origin.x, out.oy[k] = origin.y, out.oz[k] = origin.z;
    out.dx[k] = dx, out.dy[k] = dy, out.dz[k] = dz;
  }
  // Lanes past the count: no ray; their origin and direction keep an earlier batch's finite values.
  for (int k = count; k < TexelRayBatch::kWidth; ++k) out.valid[k] = 0;
}

}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ao::simd {

HWY_EXPORT(MakeTexelRays);
HWY_EXPORT(MakeHemisphereRays);

// Dispatched from the namespace of HWY_EXPORT: with a single static target (AO_NATIVE=ON)
// HWY_DYNAMIC_DISPATCH(F) is F of that target's namespace, named relative to the calling scope.
namespace {
void dispatch_texel_rays(const std::vector<detail::PatchPiece>& patch, const detail::PatchTable& table, const float (&u)[4][16], int count,
                         bool geometric, detail::TexelRayBatch& out) {
  HWY_DYNAMIC_DISPATCH(MakeTexelRays)(patch, table, u, count, geometric, out);
}
void dispatch_hemisphere_rays(Vec3 origin, Vec3 n, Vec3 ng, const float (&u)[4][16], int count, detail::TexelRayBatch& out) {
  HWY_DYNAMIC_DISPATCH(MakeHemisphereRays)(origin, n, ng, u, count, out);
}
}  // namespace

}  // namespace ao::simd

namespace ao::detail {

void make_texel_rays(const std::vector<PatchPiece>& patch, const PatchTable& table, const float (&u)[4][16], int count, bool geometric,
                     TexelRayBatch& out) {
  simd::dispatch_texel_rays(patch, table, u, count, geometric, out);
}

void make_hemisphere_rays(Vec3 origin, Vec3 n, Vec3 ng, const float (&u)[4][16], int count, TexelRayBatch& out) {
  simd::dispatch_hemisphere_rays(origin, n, ng, u, count, out);
}

}  // namespace ao::detail
#endif
