// SPDX-License-Identifier: Apache-2.0
// What the screen-space methods' kernels share (containment, volumetric and transfer: each
// method's folder holds its kernel), included by each of their sources once per target (Highway's
// "-inl.h" convention, as simd/vec_internal.h): the depth plane in vectors, a vector of a row's
// covered pixels, and the test points' offsets. Include it after simd/vec_internal.h, inside no
// namespace.
#if defined(AO_METHODS_SCREEN_SPACE_VEC_INTERNAL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef AO_METHODS_SCREEN_SPACE_VEC_INTERNAL_H_
#undef AO_METHODS_SCREEN_SPACE_VEC_INTERNAL_H_
#else
#define AO_METHODS_SCREEN_SPACE_VEC_INTERNAL_H_
#endif

#include <hwy/highway.h>

#include "ao/methods/screen_space_kernel_internal.h"
#include "ao/simd/vec_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {
namespace screen_space {

constexpr int kMaxSteps = 8;            // m: test points per ray (the methods' parameter range)
constexpr int kMaxSamples = 256;        // n: rays per pixel (kMaxScreenSpaceSamples)

// A camera-space point in vectors.
struct Point3 {
  VF x, y, z;
};

// The depth plane's constants in vectors, made once per call.
struct Plane {
  VF scale_x, scale_y, centre_x, centre_y, max_x, max_y, separation, crossing_tolerance;
  VI width;
  const float* depth;
  const float* second;
  const float* normals;
  explicit Plane(const DepthPlane& p)
      : scale_x(hn::Set(DF(), p.scale_x)), scale_y(hn::Set(DF(), p.scale_y)), centre_x(hn::Set(DF(), p.centre_x)),
        centre_y(hn::Set(DF(), p.centre_y)), max_x(hn::Set(DF(), static_cast<float>(p.width - 1))),
        max_y(hn::Set(DF(), static_cast<float>(p.height - 1))), separation(hn::Set(DF(), p.separation)),
        crossing_tolerance(hn::Set(DF(), kCrossingTolerance * p.separation)), width(hn::Set(DI(), p.width)), depth(p.depth), second(p.second),
        normals(p.normals) {}

  // Deep G-buffer (DepthPlane::second; depth_layers.h states the reading). A pixel's second-layer
  // word s2 holds a back face (0 < s2 < infinity: the visible surface is a closed solid's), a front
  // face (s2 < 0) or nothing (+infinity): then the visible surface is a sheet, or a solid thinner
  // than the separation.
  HWY_INLINE static MF back_face(VF s2) { return hn::And(hn::Gt(s2, hn::Zero(DF())), hn::Lt(s2, hn::Set(DF(), kInfinity))); }
  // Where the solid that begins at the first layer z1 ends: never behind a closed solid's front
  // (what lies past its back face is taken for solid, as with one layer), z1 + separation behind a
  // sheet.
  HWY_INLINE VF solid_end(VF z1, VF s2) const { return hn::IfThenElse(back_face(s2), hn::Set(DF(), kInfinity), hn::Add(z1, separation)); }
  // Whether s2 is where the ray leaves a closed solid seen from outside (second_layer_back_face
  // marks such a back face in the float's lowest bit): then the ray is inside that solid from the
  // visible surface (or within the separation behind it) to s2.
  HWY_INLINE static MF closed_exit(VF s2) {
    const DI di;
    const MF marked = hn::RebindMask(DF(), hn::Ne(hn::And(hn::BitCast(di, s2), hn::Set(di, 1)), hn::Zero(di)));
    return hn::And(back_face(s2), marked);
  }
  // Whether depth z lies before a closed solid's exit s2: inside that solid, however far in front
  // of z its visible surface is (AT 4.3 is left to guess about the space past the exit only).
  HWY_INLINE static MF inside_closed(VF z, VF s2) { return hn::And(closed_exit(s2), hn::Lt(z, s2)); }
  // Where the next solid begins: the front face's depth -s2, else +infinity.
  HWY_INLINE static VF next_solid(VF s2) {
    return hn::IfThenElse(hn::Gt(s2, hn::Zero(DF())), hn::Set(DF(), kInfinity), hn::Neg(s2));
  }
  // In lanes `where` (points p in the gap behind the sheet seen at pixel q; `on_sheet`: the sheet's
  // point in front of p, where the line p is read along meets q's first depth): whether that sheet
  // hides p from receiver r. It does when r lies on the camera's side of the sheet's tangent plane
  // there (q's normal) within `tol`, and the segment r -> p meets that plane where the sheet is: at
  // the meeting point's pixel the visible surface is no more than crossing_tolerance behind it. Past
  // the sheet's rim the plane runs through open space, and the surface seen there lies further back.
  HWY_INLINE MF sheet_hides(MF where, VI q, const Point3& on_sheet, const Point3& r, const Point3& p, VF tol) const {
    const DF d;
    const VI at = hn::Add(q, hn::Add(q, q));
    const VF nx = gather_where(where, normals, at), ny = gather_where(where, normals + 1, at), nz = gather_where(where, normals + 2, at);
    const auto dot_n = [&](const Point3& v) { return hn::MulAdd(nz, v.z, hn::MulAdd(ny, v.y, hn::Mul(nx, v.x))); };
    const VF w = dot_n(on_sheet);
    const VF side_r = hn::Sub(dot_n(r), w);
    const MF facing = hn::And(where, hn::Ge(side_r, hn::Neg(tol)));
    if (hn::AllFalse(d, facing)) return facing;
    const VF side_p = hn::Sub(dot_n(p), w);
    // p on r's side of the plane too (a curved sheet seen at a grazing angle): no meeting point;
    // such lanes keep one layer's answer (hidden), as t = 1 puts the meeting point at p.
    const VF den = hn::Sub(side_r, side_p);
    const VF t = hn::IfThenElse(hn::Gt(den, hn::Zero(d)), hn::Min(hn::Div(hn::Max(side_r, hn::Zero(d)), den), hn::Set(d, 1.0f)), hn::Set(d, 1.0f));
    const VF cx = hn::MulAdd(t, hn::Sub(p.x, r.x), r.x), cy = hn::MulAdd(t, hn::Sub(p.y, r.y), r.y), cz = hn::MulAdd(t, hn::Sub(p.z, r.z), r.z);
    const VF z_seen = gather_where(facing, depth, pixel(cx, cy, cz));
    const MF open = hn::Gt(z_seen, hn::Sub(crossing_tolerance, cz));  // z* > depth(c) + tolerance
    return hn::AndNot(open, facing);
  }
  // Whether point p at depth z = -p.z (lanes `where`: behind the first layer z1 of its pixel q)
  // lies in the solid as seen from receiver r: before the solid's end, past the next solid's
  // beginning, or in between where the sheet hides p from r (the sheet's point in front of p on
  // p's line of sight, p z1 / z).
  HWY_INLINE MF in_solid(VF z, VF z1, VF s2, MF where, VI q, const Point3& r, const Point3& p, VF tol) const {
    const MF known = hn::Or(hn::Lt(z, solid_end(z1, s2)), hn::Gt(z, next_solid(s2)));
    const MF gap = hn::AndNot(known, where);
    if (hn::AllFalse(DF(), gap)) return known;
    const VF s = hn::Div(z1, z);
    return hn::Or(known, sheet_hides(gap, q, {hn::Mul(p.x, s), hn::Mul(p.y, s), hn::Mul(p.z, s)}, r, p, tol));
  }

  // ScreenProjection::locate, lane-wise: the pixel of camera-space point q (clamp-to-edge: f clamped
  // to [0, size - 1] as floats before the conversion; Max returns its second operand, 0, for a NaN
  // first one on every target). `valid`: q is in front of the camera (else the pixel is meaningless).
  VI pixel(VF qx, VF qy, VF qz) const {
    const VF zero = hn::Zero(DF());
    const VF inv = hn::Div(hn::Set(DF(), -1.0f), qz);
    const VF fx = hn::MulAdd(hn::Mul(qx, inv), scale_x, centre_x);
    const VF fy = hn::NegMulAdd(hn::Mul(qy, inv), scale_y, centre_y);
    const VI ix = truncate_in_range(hn::Min(hn::Max(fx, zero), max_x));
    const VI iy = truncate_in_range(hn::Min(hn::Max(fy, zero), max_y));
    return hn::Add(hn::Mul(iy, width), ix);
  }
};

// A vector of CoveredPixels entries from k0: position, rotated frame, normal, bias.
struct Entries {
  VF px, py, pz, tx, ty, tz, bx, by, bz, nx, ny, nz, bias;
  Entries(const CoveredPixels& row, int k0) {
    const DF d;
    px = hn::Load(d, row.px.data() + k0), py = hn::Load(d, row.py.data() + k0), pz = hn::Load(d, row.pz.data() + k0);
    tx = hn::Load(d, row.tx.data() + k0), ty = hn::Load(d, row.ty.data() + k0), tz = hn::Load(d, row.tz.data() + k0);
    bx = hn::Load(d, row.bx.data() + k0), by = hn::Load(d, row.by.data() + k0), bz = hn::Load(d, row.bz.data() + k0);
    nx = hn::Load(d, row.nx.data() + k0), ny = hn::Load(d, row.ny.data() + k0), nz = hn::Load(d, row.nz.data() + k0);
    bias = hn::Load(d, row.bias.data() + k0);
  }
  // VAO eq. 5 / AT eq. 8: the test point x + X T + Y B + Z N for the offset (X, Y, Z).
  void point(float X, float Y, float Z, VF& qx, VF& qy, VF& qz) const {
    const DF d;
    const VF vx = hn::Set(d, X), vy = hn::Set(d, Y), vz = hn::Set(d, Z);
    qx = hn::MulAdd(vz, nx, hn::MulAdd(vy, bx, hn::MulAdd(vx, tx, px)));
    qy = hn::MulAdd(vz, ny, hn::MulAdd(vy, by, hn::MulAdd(vx, ty, py)));
    qz = hn::MulAdd(vz, nz, hn::MulAdd(vy, bz, hn::MulAdd(vx, tz, pz)));
  }
};

// The offsets of every test point, (j/m)(X_i, Y_i, Z_i) for step j of ray i, scaled once per call.
struct StepOffsets {
  float xyz[3 * kMaxSamples * kMaxSteps];
  StepOffsets(const TestPoints& s, int m) {
    const float inv_m = 1.0f / static_cast<float>(m);
    for (int i = 0; i < s.n; ++i)
      for (int j = 1; j <= m; ++j) {
        const float f = static_cast<float>(j) * inv_m;
        float* o = at(i, j);
        o[0] = f * s.x[i], o[1] = f * s.y[i], o[2] = f * s.z[i];
      }
  }
  float* at(int i, int j) { return &xyz[3 * (i * kMaxSteps + j - 1)]; }
  const float* at(int i, int j) const { return &xyz[3 * (i * kMaxSteps + j - 1)]; }
};

}  // namespace screen_space
}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // AO_METHODS_SCREEN_SPACE_VEC_INTERNAL_H_
