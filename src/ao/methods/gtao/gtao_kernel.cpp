// SPDX-License-Identifier: Apache-2.0
// Kernel of GTAO (gtao_internal.h; methods/gtao.cpp for the method, its parameters and deviations),
// compiled once per SIMD target: a vector of a row's covered pixels runs every slice, both sides'
// horizon searches and the inner integral with its values in registers (or, with slabs, each side's
// slabs into the slice's visibility bitmask). Multiply-adds are written
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

// One side (+1 or -1) of a slice: its tangent direction (slice_frame's of side +, negated for side
// -), its screen direction and how far it runs in the image.
struct Side {
  float sign;
  VF tx, ty, tz, dir_x, dir_y, run;
};

HWY_INLINE Side side_of(const Slice& q, float side) {
  const DF d;
  const VF sgn = hn::Set(d, side);
  return {side, hn::Mul(sgn, q.tx), hn::Mul(sgn, q.ty), hn::Mul(sgn, q.tz), hn::Mul(sgn, q.c), hn::Mul(sgn, q.si), side > 0 ? q.run_pos : q.run_neg};
}

// Step j of a side: its pixel, its depth z1, its ray (unit depth), its point's offset v from x and
// that offset in the side's frame (up: height over x's tangent plane / |n_p|; along: the component
// along the side's tangent direction); `beyond`: the step lies past the image's edge, whose last
// pixel inside it was read.
struct Sample {
  VI at;
  VF ds, rx, ry, vx, vy, vz, vv, up, along;
  MF beyond;
};

HWY_INLINE Sample sample_at(const GtaoInputs& in, const Centre& p, const Slice& q, const Side& e, int j) {
  const DF d;
  const DI di;
  const VF one = hn::Set(d, 1.0f), half = hn::Set(d, 0.5f);
  const VI izero = hn::Zero(di);
  Sample s;
  // At least one pixel from x, so the first sample is not x itself (unless x is on the border
  // and the slice leaves the image at once).
  const VF reach = hn::MulAdd(lookup16(in.step_t + 16 * j, p.pattern), p.reach, one), dist = hn::Min(reach, e.run);
  s.beyond = hn::Gt(reach, e.run);
  // The integer clamp only guards the reads against rounding at the border.
  const VI ix = hn::Min(hn::Max(truncate_in_range(hn::MulAdd(dist, e.dir_x, p.fx)), izero), hn::Set(di, in.width - 1));
  const VI iy = hn::Min(hn::Max(truncate_in_range(hn::MulAdd(dist, e.dir_y, p.fy)), izero), hn::Set(di, in.height - 1));
  s.at = hn::Add(hn::Mul(iy, hn::Set(di, in.width)), ix);
  s.ds = hn::GatherIndex(d, in.depth, s.at);
  s.rx = hn::MulAdd(hn::Set(d, in.ray_ax), hn::Add(hn::ConvertTo(d, ix), half), hn::Set(d, in.ray_bx));
  s.ry = hn::MulAdd(hn::Set(d, in.ray_ay), hn::Add(hn::ConvertTo(d, iy), half), hn::Set(d, in.ray_by));
  s.vx = hn::Sub(hn::Mul(s.ds, s.rx), p.px), s.vy = hn::Sub(hn::Mul(s.ds, s.ry), p.py), s.vz = hn::Sub(hn::Neg(s.ds), p.pz);
  s.vv = dot(s.vx, s.vy, s.vz, s.vx, s.vy, s.vz);
  s.up = hn::Mul(dot(s.vx, s.vy, s.vz, p.nx, p.ny, p.nz), q.inv_np);
  s.along = dot(s.vx, s.vy, s.vz, e.tx, e.ty, e.tz);
  return s;
}

// Whether a sample says something about the slice: a sample whose (along, up) covers less than half
// of |v|^2 lies far off the slice (a pixel centre one pixel from x can) and says little about it,
// and x's own pixel (read when x is on the border and the slice leaves the image at once) has v = 0
// up to rounding, no direction at all: both are skipped. For a sample in the slice plane along^2 +
// up^2 = |v|^2. Background (depth +inf: |v|^2 inf or NaN) fails the first test.
HWY_INLINE MF in_slice(const Centre& p, const Sample& s) {
  const DF d;
  const VF in_frame = hn::MulAdd(s.up, s.up, hn::Mul(s.along, s.along));
  return hn::And(hn::Gt(hn::Mul(hn::Set(d, 2.0f), in_frame), s.vv), hn::RebindMask(d, hn::Not(hn::Eq(s.at, p.pixel))));
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
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f), r2 = hn::Set(d, in.radius * in.radius);
  const Side e = side_of(q, side);
  VF b = one;
  for (int j = 0; j < in.steps; ++j) {
    const Sample s = sample_at(in, p, q, e, j);
    // The radius cut (step membership); only samples above the tangent plane can raise a horizon.
    const MF use = hn::And(hn::And(hn::Lt(s.vv, r2), hn::Gt(s.up, zero)), in_slice(p, s));
    const VF cos_e = hn::Div(s.along, hn::Sqrt(hn::IfThenElse(use, hn::MulAdd(s.up, s.up, hn::Mul(s.along, s.along)), one)));
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

// Slabs (docs/methods/gtao.md, "Thickness"): each sample is the front of a slab of finite depth
// along its pixel's ray, and a slice's occluded directions are the union of what its slabs cover,
// kept as a visibility bitmask (Therrien, Levesque and Gilet, "Screen Space Indirect Lighting with
// Visibility Bitmask", 2023). Our 32 points are spread evenly in the cosine-weighted measure of the
// slice's hemisphere, the paper's inner integral: point k lies at u = (k + xi) / 32 of
// G(theta) - G(gamma - pi/2) over the open a, where G(theta) = +-1/4 (-cos(2 theta - gamma) + cos gamma
// + 2 theta sin gamma) (+ for theta >= 0, - below: the inner integral from 0 to theta, signed), so
// each point carries an equal share of a and the fraction of points left uncovered, times the open a,
// is an unbiased estimate of a over the offsets xi. A slab of no end is the horizon form: it covers
// from its front down to the tangent line.
struct Measure {
  VF g_lo, scale, xi;  // bit coordinate w = (G(theta) - g_lo) scale - xi: point k covered where w's interval holds k
};

HWY_INLINE Measure slice_measure(const GtaoInputs& in, const Centre& p, const Slice& q, int s) {
  const DF d;
  const VF quarter = hn::Set(d, 0.25f), two = hn::Set(d, 2.0f);
  Measure m;
  // G(gamma - pi/2) = -1/4 (2 cos gamma + (2 gamma - pi) sin gamma); the open a is cos gamma + gamma sin gamma (>= 1).
  m.g_lo = hn::Neg(hn::Mul(quarter, hn::MulAdd(hn::MulSub(two, q.gamma, hn::Set(d, kPi)), q.sin_g, hn::Mul(two, q.cos_g))));
  m.scale = hn::Div(hn::Set(d, 32.0f), hn::MulAdd(q.gamma, q.sin_g, q.cos_g));
  m.xi = lookup16(in.sector_offset + 16 * s, p.pattern);
  return m;
}

// The bit coordinate of a point at (up, along) in side `side`'s frame of the slice (horizon()): its
// elevation e above the side's tangent line (0 below the tangent plane), theta = gamma + side (pi/2
// - e) held at 0 past the view vector (as the horizon form holds a horizon), then G(theta).
HWY_INLINE VF bit_coordinate(const Slice& q, const Measure& m, VF up, VF along, float side) {
  const DF d;
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f), two = hn::Set(d, 2.0f), quarter = hn::Set(d, 0.25f), sgn = hn::Set(d, side);
  const VF r2 = hn::MulAdd(up, up, hn::Mul(along, along));
  const MF above = hn::And(hn::Gt(up, zero), hn::Gt(r2, zero));
  const VF inv = hn::Div(one, hn::Sqrt(hn::IfThenElse(above, r2, one)));
  const VF c = hn::Min(hn::Max(hn::IfThenElse(above, hn::Mul(along, inv), one), hn::Set(d, -1.0f)), one);
  const VF sn = hn::IfThenElseZero(above, hn::Mul(up, inv));
  const VF raw = hn::MulAdd(sgn, hn::Sub(hn::Set(d, kHalfPi), fast_acos(c)), q.gamma);
  const MF past = side > 0 ? hn::Lt(raw, zero) : hn::Gt(raw, zero);
  const VF theta = hn::IfThenZeroElse(past, raw);
  // cos(2 theta - gamma) = -(cos gamma cos 2e + side sin gamma sin 2e); at theta = 0, cos gamma.
  const VF cos2e = hn::MulSub(two, hn::Mul(c, c), one), sin2e = hn::Mul(two, hn::Mul(c, sn));
  const VF cos2 = hn::IfThenElse(past, q.cos_g, hn::Neg(hn::MulAdd(q.cos_g, cos2e, hn::Mul(sgn, hn::Mul(q.sin_g, sin2e)))));
  const VF f = hn::Mul(quarter, hn::MulAdd(hn::Mul(two, theta), q.sin_g, hn::Sub(q.cos_g, cos2)));
  return hn::MulSub(hn::Sub(side > 0 ? f : hn::Neg(f), m.g_lo), m.scale, m.xi);
}

// Bits [0, k) for k in [0, 32].
HWY_INLINE VU bits_below(VI k) {
  const DU du;
  const DI di;
  const VU one = hn::Set(du, 1u);
  const VU low = hn::Sub(one << hn::BitCast(du, hn::Min(k, hn::Set(di, 31))), one);
  return hn::IfThenElse(hn::RebindMask(du, hn::Gt(k, hn::Set(di, 31))), hn::Set(du, ~0u), low);
}

// The points k with k in [a, b) (a <= b, bit coordinates), where `mask` is set.
HWY_INLINE VU bits_between(MF mask, VF a, VF b) {
  const DF d;
  const DI di;
  const VF zero = hn::Zero(d), top = hn::Set(d, 32.0f);
  const VI lo = hn::ConvertTo(di, hn::Min(hn::Max(hn::Ceil(a), zero), top));
  const VI hi = hn::ConvertTo(di, hn::Min(hn::Max(hn::Ceil(b), zero), top));
  return hn::IfThenElseZero(hn::RebindMask(DU(), mask), hn::AndNot(bits_below(lo), bits_below(hi)));
}

// The depth interval [z1, zb] of a sample's slab (zb = +inf: without end) and the front z2 of its
// second, endless slab (+inf: none). One layer: zb = z1 + thickness. Two, by the second-layer value
// s2 (GBuffer::second_depth): nothing behind, z1 + separation (a sheet); a front face at |s2|, z1 +
// separation and a second slab from |s2| on; a closed solid's exit, s2; any other back face, no end
// (the horizon form, as one layer reads every sample). Past the image's edge the slice reads its last
// pixel inside (clamp-to-edge, slice_frame): what lies beyond is not known, and the horizon form's
// endless solid stands for it, as with one layer.
HWY_INLINE void slab_depths(const GtaoInputs& in, const Sample& s, VF& zb, VF& z2) {
  const DF d;
  const DI di;
  const VF zero = hn::Zero(d), inf = hn::Set(d, kInfinity);
  zb = hn::Add(s.ds, hn::Set(d, in.second ? in.separation : in.thickness)), z2 = inf;
  if (in.second) {
    const VF s2 = hn::GatherIndex(d, in.second, s.at);
    const MF back = hn::And(hn::Gt(s2, zero), hn::Lt(s2, inf));
    const MF exit = hn::RebindMask(d, hn::Ne(hn::And(hn::BitCast(di, s2), hn::Set(di, 1)), hn::Zero(di)));
    zb = hn::IfThenElse(back, hn::IfThenElse(exit, s2, inf), zb);
    z2 = hn::IfThenElse(hn::Lt(s2, zero), hn::Neg(s2), inf);
  }
  zb = hn::IfThenElse(s.beyond, inf, zb);
}

// The bit coordinates [lo, hi] a finite slab [z1, zb] covers within R (lo > hi where `finite` is not
// set or nothing is within R): the segment v + lambda dv, dv = (zb / z1 - 1) times the front point,
// lambda in [0, 1], clipped to the ball of radius R about x (a quadratic in lambda). Its ends are
// mostly its front (lambda = 0, w_front exactly) and a point behind it; a vector with no lane to
// clip, or none whose front lies outside R, skips their work (the values are the same).
HWY_INLINE void segment_range(const GtaoInputs& in, const Centre& p, const Slice& q, const Measure& m, const Side& e, const Sample& s,
                              MF finite, VF zb, VF w_front, VF& lo, VF& hi) {
  const DF d;
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f), inf = hn::Set(d, kInfinity);
  const VF k = hn::IfThenElseZero(finite, hn::Sub(hn::Div(zb, s.ds), one));
  const VF dx = hn::Mul(k, hn::Mul(s.ds, s.rx)), dy = hn::Mul(k, hn::Mul(s.ds, s.ry)), dz = hn::Mul(k, hn::Neg(s.ds));
  const VF qa = dot(dx, dy, dz, dx, dy, dz), qb = dot(s.vx, s.vy, s.vz, dx, dy, dz);
  const VF disc = hn::NegMulAdd(qa, hn::Sub(s.vv, hn::Set(d, in.radius * in.radius)), hn::Mul(qb, qb));
  const MF meets = hn::And(finite, hn::And(hn::Gt(disc, zero), hn::Gt(qa, zero)));
  const VF root = hn::Sqrt(hn::IfThenElseZero(meets, disc)), inv_a = hn::Div(one, hn::IfThenElse(meets, qa, one));
  const VF l0 = hn::Max(hn::Mul(hn::Neg(hn::Add(qb, root)), inv_a), zero), l1 = hn::Min(hn::Mul(hn::Sub(root, qb), inv_a), one);
  const MF clipped = hn::And(meets, hn::Lt(l0, l1));
  lo = inf, hi = hn::Neg(inf);
  if (hn::AllFalse(d, clipped)) return;
  const VF d_up = hn::Mul(dot(dx, dy, dz, p.nx, p.ny, p.nz), q.inv_np), d_along = dot(dx, dy, dz, e.tx, e.ty, e.tz);
  VF w0 = w_front;
  if (!hn::AllTrue(d, hn::Or(hn::Not(clipped), hn::Eq(l0, zero))))
    w0 = bit_coordinate(q, m, hn::MulAdd(l0, d_up, s.up), hn::MulAdd(l0, d_along, s.along), e.sign);
  const VF w1 = bit_coordinate(q, m, hn::MulAdd(l1, d_up, s.up), hn::MulAdd(l1, d_along, s.along), e.sign);
  lo = hn::IfThenElse(clipped, hn::Min(w0, w1), lo), hi = hn::IfThenElse(clipped, hn::Max(w0, w1), hi);
}

// The bit coordinates [lo, hi] an endless slab whose front has coordinate w covers (where `counts`:
// its front is within R): from there to the side's end (e = 0), as a horizon does; lo > hi elsewhere.
HWY_INLINE void endless_range(const Side& e, MF counts, VF w, VF& lo, VF& hi) {
  const DF d;
  const VF inf = hn::Set(d, kInfinity), side_end = hn::Set(d, e.sign > 0 ? 33.0f : -1.0f);  // beyond the side's last point
  lo = hn::IfThenElse(counts, hn::Min(w, side_end), inf), hi = hn::IfThenElse(counts, hn::Max(w, side_end), hn::Neg(inf));
}

// The second, endless slab of a sample, from a front face at depth z2 on (where `behind`).
HWY_INLINE void second_slab_range(const GtaoInputs& in, const Centre& p, const Slice& q, const Measure& m, const Side& e, const Sample& s,
                                  MF behind, VF z2, VF& lo, VF& hi) {
  const DF d;
  const VF zf = hn::IfThenElseZero(behind, z2);
  const VF fx = hn::Sub(hn::Mul(zf, s.rx), p.px), fy = hn::Sub(hn::Mul(zf, s.ry), p.py), fz = hn::Sub(hn::Neg(zf), p.pz);
  const VF w = bit_coordinate(q, m, hn::Mul(dot(fx, fy, fz, p.nx, p.ny, p.nz), q.inv_np), dot(fx, fy, fz, e.tx, e.ty, e.tz), e.sign);
  endless_range(e, hn::And(behind, hn::Lt(dot(fx, fy, fz, fx, fy, fz), hn::Set(d, in.radius * in.radius))), w, lo, hi);
}

// What one side's slabs cover of the slice's bitmask (slab_depths, segment_range, endless_range).
// Between a sample and the previous one the surface runs on where their slabs overlap in depth (a
// sheet or a solid seen across both rays, not a silhouette's step): the solid between the two rays
// covers what lies between their slabs too.
HWY_INLINE VU slab_bits(const GtaoInputs& in, const Centre& p, const Slice& q, const Measure& m, float side) {
  const DF d;
  const VF inf = hn::Set(d, kInfinity);
  const Side e = side_of(q, side);
  VU bits = hn::Zero(DU());
  // The previous sample's depth interval and the bit coordinates its slab covers (lo > hi: none).
  VF prev_z1 = inf, prev_zb = hn::Zero(d), prev_lo = inf, prev_hi = hn::Neg(inf);
  for (int j = 0; j < in.steps; ++j) {
    const Sample s = sample_at(in, p, q, e, j);
    const MF sample = hn::And(in_slice(p, s), hn::Lt(s.ds, inf));
    VF zb, z2;
    slab_depths(in, s, zb, z2);
    const MF endless = hn::And(sample, hn::Eq(zb, inf));
    const VF w_front = bit_coordinate(q, m, s.up, s.along, side);
    VF lo, hi, elo, ehi;
    segment_range(in, p, q, m, e, s, hn::AndNot(endless, sample), zb, w_front, lo, hi);
    endless_range(e, hn::And(endless, hn::Lt(s.vv, hn::Set(d, in.radius * in.radius))), w_front, elo, ehi);
    lo = hn::Min(lo, elo), hi = hn::Max(hi, ehi);  // a sample's slab is one or the other
    bits = hn::Or(bits, bits_between(hn::Le(lo, hi), lo, hi));
    const MF joined = hn::And(hn::And(hn::Le(s.ds, prev_zb), hn::Le(prev_z1, zb)), hn::And(hn::Le(lo, hi), hn::Le(prev_lo, prev_hi)));
    bits = hn::Or(bits, bits_between(joined, hn::Min(lo, prev_lo), hn::Max(hi, prev_hi)));
    const MF kept = hn::Not(sample);  // a skipped sample leaves the previous one to join the next
    prev_z1 = hn::IfThenElse(kept, prev_z1, s.ds), prev_zb = hn::IfThenElse(kept, prev_zb, zb);
    prev_lo = hn::IfThenElse(kept, prev_lo, lo), prev_hi = hn::IfThenElse(kept, prev_hi, hi);
    // The second slab, from a front face at z2 on without end.
    const MF behind = hn::And(sample, hn::Lt(z2, inf));
    if (hn::AllFalse(d, behind)) continue;
    second_slab_range(in, p, q, m, e, s, behind, z2, elo, ehi);
    bits = hn::Or(bits, bits_between(hn::Le(elo, ehi), elo, ehi));
  }
  return bits;
}

// The slice's visibility with slabs: |n_p| a_open times the fraction of its points left uncovered,
// into sum_v; |n_p| a_open into sum_open.
HWY_INLINE void add_slab_slice(const GtaoInputs& in, const Centre& p, const Slice& q, int s, VF& sum_v, VF& sum_open) {
  const DF d;
  const DI di;
  const Measure m = slice_measure(in, p, q, s);
  const VU bits = hn::Or(slab_bits(in, p, q, m, 1.0f), slab_bits(in, p, q, m, -1.0f));
  const VF covered = hn::ConvertTo(d, hn::BitCast(di, hn::PopulationCount(bits)));
  const VF open = hn::Mul(q.len, hn::MulAdd(q.gamma, q.sin_g, q.cos_g));
  sum_v = hn::MulAdd(open, hn::NegMulAdd(covered, hn::Set(d, 1.0f / 32.0f), hn::Set(d, 1.0f)), sum_v);
  sum_open = hn::Add(sum_open, open);
}

}  // namespace

void GtaoRow(const GtaoInputs& in, int y, int x0, int x1, float* out) {
  const DF d;
  const DI di;
  const int lanes = static_cast<int>(hn::Lanes(d));
  HWY_ALIGN std::int32_t index[kMaxGtaoSegment + kMaxLanes];
  const int n = compact_covered(in, y, x0, x1, index);
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f);
  const bool slabs = in.thickness > 0 || in.second != nullptr;
  HWY_ALIGN float v[kMaxLanes];
  for (int k0 = 0; k0 < n; k0 += lanes) {
    const Centre p = load_centre(in, y, hn::Add(hn::Set(di, x0), hn::Load(di, index + k0)));
    VF sum_v = zero, sum_open = zero;
    for (int s = 0; s < in.slices; ++s) {
      const Slice q = slice_frame(in, p, s);
      if (slabs) add_slab_slice(in, p, q, s, sum_v, sum_open);
      else add_inner_integral(q, horizon(in, p, q, 1.0f), horizon(in, p, q, -1.0f), sum_v, sum_open);
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
