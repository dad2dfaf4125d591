// SPDX-License-Identifier: Apache-2.0
// Kernel of GTAO (gtao_internal.h; methods/gtao.cpp for the method, its parameters and deviations),
// compiled once per SIMD target: a vector of a row's covered pixels runs every slice, both sides'
// horizon searches and the inner integral with its values in registers. Multiply-adds are written
// out (MulAdd); this file is compiled without contraction, so targets with FMA agree bit for bit.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/methods/gtao/gtao_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <algorithm>

#include <hwy/highway.h>

#include "ao/core/error.h"
#include "ao/core/math.h"
#include "ao/simd/aligned_internal.h"
#include "ao/methods/gtao/gtao_kernel_internal.h"
#include "ao/methods/gtao/gtao_shared.h"
#include "ao/simd/vec_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

namespace {

constexpr float kHalfPi = 0.5f * kPi;

// acos on [-1, 1] by Abramowitz & Stegun 4.4.46 (gtao_shared.h), branch-free.
HWY_INLINE VF fast_acos(VF x) {
  const DF d;
  const VF a = hn::Min(hn::Abs(x), hn::Set(d, 1.0f));
  VF p = hn::Set(d, shared::kAcosFit7);
  for (float c : {shared::kAcosFit6, shared::kAcosFit5, shared::kAcosFit4, shared::kAcosFit3, shared::kAcosFit2, shared::kAcosFit1, shared::kAcosFit0})
    p = hn::MulAdd(p, a, hn::Set(d, c));
  const VF r = hn::Mul(p, hn::Sqrt(hn::Sub(hn::Set(d, 1.0f), a)));
  return hn::IfThenElse(hn::Lt(x, hn::Zero(d)), hn::Sub(hn::Set(d, kPi), r), r);
}

HWY_INLINE VF dot(VF ax, VF ay, VF az, VF bx, VF by, VF bz) { return hn::MulAdd(az, bz, hn::MulAdd(ay, by, hn::Mul(ax, bx))); }

// Compaction of row y's segment [x0, x1) to its covered pixels (background costs the sample loops
// nothing): their offsets from x0 in index[0, n), the padding entries up to a whole vector repeat
// the segment's first pixel and are never written. Returns n.
int compact_covered(const GtaoInputs& in, int y, int x0, int x1, std::int32_t* index) {
  AO_ASSERT(x1 - x0 <= kMaxGtaoSegment);
  const std::uint32_t* id = in.object_id + static_cast<std::size_t>(y) * in.width + x0;
  int n = 0;
  for (int j = 0; j < x1 - x0; ++j) {
    index[n] = j;
    n += id[j] != 0 ? 1 : 0;
  }
  std::fill(index + n, index + padded(n), 0);
  return n;
}

// A vector of covered pixels x: camera-space position and normal, w_o, pixel coordinates and the
// screen radius.
struct Centre {
  VI pixel, pattern;
  VF fx, fy, px, py, pz, nx, ny, nz, wx, wy, wz, reach;
};

HWY_INLINE Centre load_centre(const GtaoInputs& in, int y, VI x) {
  const DF d;
  const DI di;
  const VF one = hn::Set(d, 1.0f), half = hn::Set(d, 0.5f);
  Centre p;
  p.pixel = hn::Add(hn::Set(di, y * in.width), x);
  // x, camera space: depth * the ray through the pixel centre (its samples are rebuilt the same
  // way, so x and its samples agree exactly on a plane).
  const VF depth = hn::GatherIndex(d, in.depth, p.pixel);
  p.fx = hn::Add(hn::ConvertTo(d, x), half), p.fy = hn::Set(d, static_cast<float>(y) + 0.5f);
  p.px = hn::Mul(depth, hn::MulAdd(hn::Set(d, in.ray_ax), p.fx, hn::Set(d, in.ray_bx)));
  p.py = hn::Mul(depth, hn::MulAdd(hn::Set(d, in.ray_ay), p.fy, hn::Set(d, in.ray_by))), p.pz = hn::Neg(depth);
  const VI p3 = hn::Mul(p.pixel, hn::Set(di, 3));
  p.nx = hn::GatherIndex(d, in.normal, p3), p.ny = hn::GatherIndex(d, in.normal + 1, p3), p.nz = hn::GatherIndex(d, in.normal + 2, p3);
  p.pattern = hn::Add(hn::Set(di, (y & 3) * 4), hn::And(x, hn::Set(di, 3)));
  // w_o: the unit vector from x to the eye.
  const VF inv = hn::Div(one, hn::Sqrt(dot(p.px, p.py, p.pz, p.px, p.py, p.pz)));
  p.wx = hn::Mul(hn::Neg(p.px), inv), p.wy = hn::Mul(hn::Neg(p.py), inv), p.wz = hn::Mul(hn::Neg(p.pz), inv);
  // R at depth z spans R px_per_unit / z pixels; the samples reach up to one pixel less.
  const VF radius_px = hn::Div(hn::Set(d, in.radius * in.px_per_unit), depth);
  p.reach = hn::Max(hn::Sub(radius_px, one), hn::Zero(d));
  return p;
}

// One slice at a vector of pixels: its screen direction (c, si), |n_p|, gamma, the tangent
// direction of side + (side - is its negative), and how far (pixels) each side runs in the image.
struct Slice {
  VF c, si, len, cos_g, sin_g, gamma, inv_np, tx, ty, tz, run_pos, run_neg;
};

// How far (pixels) a slice runs from coordinate f along direction component dir before leaving
// [0, size_in]: towards + (dir > 0 runs to size_in, dir < 0 to 0) and towards -.
HWY_INLINE void runs(VF f, VF dir, VF size_in, VF& run_pos, VF& run_neg) {
  const DF d;
  const VF zero = hn::Zero(d), inf = hn::Set(d, kInfinity);
  const MF pos = hn::Gt(dir, zero), neg = hn::Lt(dir, zero);
  run_pos = hn::IfThenElse(pos, hn::Div(hn::Sub(size_in, f), dir), hn::IfThenElse(neg, hn::Div(f, hn::Neg(dir)), inf));
  run_neg = hn::IfThenElse(pos, hn::Div(f, dir), hn::IfThenElse(neg, hn::Div(hn::Sub(size_in, f), hn::Neg(dir)), inf));
}

HWY_INLINE Slice slice_frame(const GtaoInputs& in, const Centre& p, int s) {
  const DF d;
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f), minus_one = hn::Set(d, -1.0f);
  Slice q;
  // The slice plane, the projected normal n_p, gamma, and the tangent directions of both sides.
  q.c = lookup16(in.dir_c + 16 * s, p.pattern), q.si = lookup16(in.dir_s + 16 * s, p.pattern);
  // The screen direction (c, si) (pixel y down) is the camera-space direction (c, -si, 0) of the
  // image plane; with w_o it spans the slice plane. Its part orthogonal to w_o, o, is the slice's
  // theta = +pi/2 axis.
  const VF dw = hn::NegMulAdd(q.si, p.wy, hn::Mul(q.c, p.wx));
  VF ox = hn::NegMulAdd(dw, p.wx, q.c), oy = hn::NegMulAdd(dw, p.wy, hn::Neg(q.si)), oz = hn::Neg(hn::Mul(dw, p.wz));
  const VF oinv = hn::Div(one, hn::Sqrt(dot(ox, oy, oz, ox, oy, oz)));
  ox = hn::Mul(ox, oinv), oy = hn::Mul(oy, oinv), oz = hn::Mul(oz, oinv);
  // Axis of the slice plane (unit: o and w_o are orthonormal), and n_p = n minus its axis part.
  const VF qx = hn::NegMulAdd(oz, p.wy, hn::Mul(oy, p.wz)), qy = hn::NegMulAdd(ox, p.wz, hn::Mul(oz, p.wx));
  const VF qz = hn::NegMulAdd(oy, p.wx, hn::Mul(ox, p.wy));
  const VF na = dot(p.nx, p.ny, p.nz, qx, qy, qz);
  const VF npx = hn::NegMulAdd(na, qx, p.nx), npy = hn::NegMulAdd(na, qy, p.ny), npz = hn::NegMulAdd(na, qz, p.nz);
  q.len = hn::Sqrt(dot(npx, npy, npz, npx, npy, npz));
  const MF has_np = hn::Gt(q.len, zero);
  // gamma = angle of n_p from w_o, towards o when positive. cos gamma is clamped at 0: a normal
  // facing away from the eye (interpolated normals at silhouettes) is taken as perpendicular to
  // the view, so the hemisphere stays on the visible side.
  q.cos_g = hn::IfThenElse(has_np, hn::Min(hn::Max(hn::Div(dot(npx, npy, npz, p.wx, p.wy, p.wz), q.len), zero), one), one);
  const VF sign = hn::IfThenElse(hn::Ge(dot(npx, npy, npz, ox, oy, oz), zero), one, minus_one);
  q.sin_g = hn::Mul(sign, hn::Sqrt(hn::NegMulAdd(q.cos_g, q.cos_g, one)));
  q.gamma = hn::Mul(sign, fast_acos(q.cos_g));
  q.inv_np = hn::IfThenElseZero(has_np, hn::Div(one, q.len));
  // The slice's tangent direction at theta = gamma + pi/2 (side +): cos(theta) w_o + sin(theta) o;
  // side - (theta = gamma - pi/2) has the opposite one.
  q.tx = hn::MulSub(q.cos_g, ox, hn::Mul(q.sin_g, p.wx)), q.ty = hn::MulSub(q.cos_g, oy, hn::Mul(q.sin_g, p.wy));
  q.tz = hn::MulSub(q.cos_g, oz, hn::Mul(q.sin_g, p.wz));
  // Clamp-to-edge along the slice: how far (pixels) each side runs before leaving the image.
  // Samples beyond read the slice's last pixel inside it, a real surface point in the slice
  // plane, rather than counting the space beyond the frame as empty. Coordinates stay below the
  // image's size less 1e-3 (just inside the last pixel).
  VF run_x_pos, run_x_neg, run_y_pos, run_y_neg;
  runs(p.fx, q.c, hn::Set(d, static_cast<float>(in.width) - 1e-3f), run_x_pos, run_x_neg);
  runs(p.fy, q.si, hn::Set(d, static_cast<float>(in.height) - 1e-3f), run_y_pos, run_y_neg);
  q.run_pos = hn::Min(run_x_pos, run_y_pos), q.run_neg = hn::Min(run_x_neg, run_y_neg);
  return q;
}

// The horizon search on one side (+1 or -1). A horizon is stored as its elevation e above the
// tangent line of its side (theta = gamma +- pi/2 -+ e), kept as cos e, which falls as e rises
// through [0, pi]: the lowest cos e of the samples within R above the tangent plane, 1 (the
// tangent plane itself) when none is. A sample's elevation is atan2(its height over x's tangent
// plane / |n_p|, its component along the side's tangent direction): for a sample in the slice plane
// exactly the angle the paper's horizon measures; a pixel centre up to half a pixel off the
// slice's screen line that lies in x's tangent plane still never raises the horizon.
HWY_INLINE VF horizon(const GtaoInputs& in, const Centre& p, const Slice& q, float side) {
  const DF d;
  const DI di;
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f), half = hn::Set(d, 0.5f), two = hn::Set(d, 2.0f), sgn = hn::Set(d, side);
  const VF ax = hn::Set(d, in.ray_ax), bx = hn::Set(d, in.ray_bx), ay = hn::Set(d, in.ray_ay), by = hn::Set(d, in.ray_by);
  const VF r2 = hn::Set(d, in.radius * in.radius);
  const VI max_ix = hn::Set(di, in.width - 1), max_iy = hn::Set(di, in.height - 1), width = hn::Set(di, in.width), izero = hn::Zero(di);
  const VF tx = hn::Mul(sgn, q.tx), ty = hn::Mul(sgn, q.ty), tz = hn::Mul(sgn, q.tz);
  const VF run = side > 0 ? q.run_pos : q.run_neg;
  const VF dir_x = hn::Mul(sgn, q.c), dir_y = hn::Mul(sgn, q.si);
  VF b = one;
  for (int j = 0; j < in.steps; ++j) {
    // At least one pixel from x, so the first sample is not x itself (unless x is on the border
    // and the slice leaves the image at once).
    const VF dist = hn::Min(hn::MulAdd(lookup16(in.step_t + 16 * j, p.pattern), p.reach, one), run);
    // The integer clamp only guards the reads against rounding at the border.
    const VI ix = hn::Min(hn::Max(truncate_in_range(hn::MulAdd(dist, dir_x, p.fx)), izero), max_ix);
    const VI iy = hn::Min(hn::Max(truncate_in_range(hn::MulAdd(dist, dir_y, p.fy)), izero), max_iy);
    const VI at = hn::Add(hn::Mul(iy, width), ix);
    const VF ds = hn::GatherIndex(d, in.depth, at);
    const VF vx = hn::Sub(hn::Mul(ds, hn::MulAdd(ax, hn::Add(hn::ConvertTo(d, ix), half), bx)), p.px);
    const VF vy = hn::Sub(hn::Mul(ds, hn::MulAdd(ay, hn::Add(hn::ConvertTo(d, iy), half), by)), p.py);
    const VF vz = hn::Sub(hn::Neg(ds), p.pz);
    const VF vv = dot(vx, vy, vz, vx, vy, vz);
    const VF up = hn::Mul(dot(vx, vy, vz, p.nx, p.ny, p.nz), q.inv_np);
    const VF along = dot(vx, vy, vz, tx, ty, tz);
    // The radius cut (step membership); background (depth +inf: vv inf or NaN) fails it. Only
    // samples above the tangent plane can raise a horizon. A sample whose (along, up) covers less
    // than half of |v|^2 lies far off the slice (a pixel centre one pixel from x can) and says
    // little about it, and x's own pixel (read when x is on the border and the slice leaves the
    // image at once) has v = 0 up to rounding, no direction at all: both are skipped. For a sample
    // in the slice plane along^2 + up^2 = |v|^2.
    const VF in_frame = hn::MulAdd(up, up, hn::Mul(along, along));
    const MF use = hn::And(hn::And(hn::Lt(vv, r2), hn::Gt(up, zero)),
                           hn::And(hn::Gt(hn::Mul(two, in_frame), vv), hn::RebindMask(d, hn::Not(hn::Eq(at, p.pixel)))));
    const VF cos_e = hn::Div(along, hn::Sqrt(hn::IfThenElse(use, in_frame, one)));
    b = hn::IfThenElse(use, hn::Min(b, cos_e), b);
  }
  return b;
}

// The inner integral between the horizons of sides + (cos e2 = best_pos) and - (cos e1 =
// best_neg), times |n_p| (the outer integrand), into sum_v; the same for the open hemisphere into
// sum_open.
HWY_INLINE void add_inner_integral(const Slice& q, VF best_pos, VF best_neg, VF& sum_v, VF& sum_open) {
  const DF d;
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f), two = hn::Set(d, 2.0f), quarter = hn::Set(d, 0.25f);
  const VF minus_one = hn::Set(d, -1.0f), half_pi = hn::Set(d, kHalfPi);
  const VF c2 = hn::Min(hn::Max(best_pos, minus_one), one), c1 = hn::Min(hn::Max(best_neg, minus_one), one);
  const VF e2 = fast_acos(c2), e1 = fast_acos(c1);
  // h2 = gamma + pi/2 - e2 and h1 = gamma - pi/2 + e1: inside [gamma - pi/2, gamma + pi/2] (the
  // paper's clamp to the hemisphere) by construction. A horizon past the view vector (possible
  // only for samples off the slice plane) is held at theta = 0: x is seen from the eye, so the
  // view direction is free.
  const VF h2_raw = hn::Sub(hn::Add(q.gamma, half_pi), e2), h1_raw = hn::Add(hn::Sub(q.gamma, half_pi), e1);
  const MF past2 = hn::Lt(h2_raw, zero), past1 = hn::Gt(h1_raw, zero);
  const VF h2 = hn::IfThenZeroElse(past2, h2_raw), h1 = hn::IfThenZeroElse(past1, h1_raw);
  // cos(2 h2 - gamma) = -(cos gamma cos 2e2 + sin gamma sin 2e2) and cos(2 h1 - gamma) =
  // -(cos gamma cos 2e1 - sin gamma sin 2e1), with cos 2e = 2c^2 - 1 and sin 2e = 2c sqrt(1 - c^2)
  // (e in [0, pi]); at theta = 0, cos(-gamma) = cos gamma.
  const VF s2 = hn::Sqrt(hn::Max(hn::NegMulAdd(c2, c2, one), zero)), s1 = hn::Sqrt(hn::Max(hn::NegMulAdd(c1, c1, one), zero));
  const VF cos2 = hn::IfThenElse(past2, q.cos_g,
                                 hn::Neg(hn::MulAdd(hn::Mul(hn::Mul(two, c2), s2), q.sin_g, hn::Mul(hn::MulSub(two, hn::Mul(c2, c2), one), q.cos_g))));
  const VF cos1 = hn::IfThenElse(past1, q.cos_g,
                                 hn::Neg(hn::NegMulAdd(hn::Mul(hn::Mul(two, c1), s1), q.sin_g, hn::Mul(hn::MulSub(two, hn::Mul(c1, c1), one), q.cos_g))));
  // The inner integral (both halves), times |n_p| (the outer integrand).
  const VF a1 = hn::MulAdd(hn::Mul(two, h1), q.sin_g, hn::Add(hn::Neg(cos1), q.cos_g));
  const VF a2 = hn::MulAdd(hn::Mul(two, h2), q.sin_g, hn::Add(hn::Neg(cos2), q.cos_g));
  const VF a = hn::MulAdd(quarter, a2, hn::Mul(quarter, a1));
  // Its value for the open hemisphere, h = gamma -+ pi/2: cos gamma + gamma sin gamma.
  const VF open = hn::MulAdd(q.gamma, q.sin_g, q.cos_g);
  sum_v = hn::MulAdd(q.len, a, sum_v);
  sum_open = hn::MulAdd(q.len, open, sum_open);
}

}  // namespace

void GtaoRow(const GtaoInputs& in, int y, int x0, int x1, float* out) {
  const DF d;
  const DI di;
  const int lanes = static_cast<int>(hn::Lanes(d));
  HWY_ALIGN std::int32_t index[kMaxGtaoSegment + kMaxLanes];
  const int n = compact_covered(in, y, x0, x1, index);
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f);
  HWY_ALIGN float v[kMaxLanes];
  for (int k0 = 0; k0 < n; k0 += lanes) {
    const Centre p = load_centre(in, y, hn::Add(hn::Set(di, x0), hn::Load(di, index + k0)));
    VF sum_v = zero, sum_open = zero;
    for (int s = 0; s < in.slices; ++s) {
      const Slice q = slice_frame(in, p, s);
      add_inner_integral(q, horizon(in, p, q, 1.0f), horizon(in, p, q, -1.0f), sum_v, sum_open);
    }
    // V = sum |n_p| a / sum |n_p| a_open: the slices' own estimate of the open integral as the
    // normaliser (its limit is 1), so an open plane is 1 at any slice count.
    const VF vis = hn::IfThenElse(hn::Gt(sum_open, zero), hn::Min(hn::Max(hn::Div(sum_v, sum_open), zero), one), one);
    hn::Store(vis, d, v);
    for (int k = 0; k < std::min(lanes, n - k0); ++k) out[index[k0 + k]] = v[k];
  }
}

}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ao::simd {

HWY_EXPORT(GtaoRow);

void gtao_row(const GtaoInputs& in, int y, int x0, int x1, float* v) { HWY_DYNAMIC_DISPATCH(GtaoRow)(in, y, x0, x1, v); }

}  // namespace ao::simd
#endif
