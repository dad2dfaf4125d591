// Kernels of the depth-buffer screen-space methods (screen_space_internal.h states what each
// computes, in the papers' terms): containment AO (VAO eq. 5, AT sec. 4), volumetric AO's pipes
// (VAO eq. 6-7) and ambient transfer (AT eq. 8-9), compiled once per SIMD target. Lanes are a row's
// covered pixels; a kernel keeps a vector of pixels' values and sums in registers through all of
// their samples, so the gathers of successive test points are independent and several are in
// flight at once. Multiply-adds are written out (MulAdd) in the order the scalar reading of each
// equation gives; this file is compiled without contraction, so targets with FMA agree bit for bit.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/simd/screen_space.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <algorithm>
#include <cstring>

#include <hwy/highway.h>

#include "ao/simd/screen_space_internal.h"
#include "ao/simd/vec_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

namespace {

constexpr int kMaxSteps = 8;            // m: test points per ray (the methods' parameter range)
constexpr int kMaxSamples = 256;        // n: rays per pixel (kMaxScreenSpaceSamples)
constexpr std::uint32_t kPaletteMask = 0x1F;  // a palette index's bits in a packed depth word

// Rec. 709 luminance of W: the method's scalar visibility.
inline float luminance(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }

// The depth plane's constants in vectors, made once per call.
struct Plane {
  VF scale_x, scale_y, centre_x, centre_y, max_x, max_y, separation;
  VI width;
  const float* depth;
  const float* second;
  explicit Plane(const DepthPlane& p)
      : scale_x(hn::Set(DF(), p.scale_x)), scale_y(hn::Set(DF(), p.scale_y)), centre_x(hn::Set(DF(), p.centre_x)),
        centre_y(hn::Set(DF(), p.centre_y)), max_x(hn::Set(DF(), static_cast<float>(p.width - 1))),
        max_y(hn::Set(DF(), static_cast<float>(p.height - 1))), separation(hn::Set(DF(), p.separation)), width(hn::Set(DI(), p.width)),
        depth(p.depth), second(p.second) {}

  // Deep G-buffer (DepthPlane::second): where the solid that begins at a pixel's first layer z1
  // ends, given the pixel's second-layer word s2: s2 itself for a back face (s2 > 0, +infinity
  // without a surface behind), z1 + separation for a front face.
  HWY_INLINE VF solid_end(VF z1, VF s2) const { return hn::IfThenElse(hn::Gt(s2, hn::Zero(DF())), s2, hn::Add(z1, separation)); }
  // Where the next solid begins: the front face's depth -s2, else +infinity.
  HWY_INLINE static VF next_solid(VF s2) {
    return hn::IfThenElse(hn::Gt(s2, hn::Zero(DF())), hn::Set(DF(), kInfinity), hn::Neg(s2));
  }
  // Whether depth z, behind the first layer z1, lies in the solid: before its end or past the next
  // solid's beginning.
  HWY_INLINE MF in_solid(VF z, VF z1, VF s2) const { return hn::Or(hn::Lt(z, solid_end(z1, s2)), hn::Gt(z, next_solid(s2))); }

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

// The covered pixels of row y's segment [first, last), compacted into the row's entries: their
// offsets, positions, normals and rotations (the row's rotations repeat every 4 pixels). A vector of
// pixels all covered (the common case inside an object) is copied whole, its 12-byte position and
// normal records de-interleaved; a vector partly covered pixel by pixel, branch-free; no gathers
// (on some CPUs, Zen 4 among them, a gather of 16 lanes costs more than 16 scalar loads). Entries
// past the count up to a whole vector are a harmless point: one unit in front of the camera,
// facing it, offset 0. Returns the padded count.
int load_entries(CoveredPixels& row, const GBuffer& g, int y, int first, int last, const Rotations16& rotations) {
  const DF d;
  const DI di;
  const DU du;
  const int n = static_cast<int>(hn::Lanes(d)), len = last - first;
  const float* pos = &g.position(first, y).x;
  const float* nrm = &g.normal(first, y).x;
  const std::uint32_t* id = &g.object_id(first, y);
  const float* rot_c = rotations.c + (y & 3) * 4;
  const float* rot_s = rotations.s + (y & 3) * 4;
  // Pixel first + j has rotation (first + j) & 3: the pattern from j & 3 on, for a whole vector.
  HWY_ALIGN float pattern_c[kMaxLanes + 3], pattern_s[kMaxLanes + 3];
  for (int l = 0; l < n + 3; ++l) pattern_c[l] = rot_c[(first + l) & 3], pattern_s[l] = rot_s[(first + l) & 3];
  int* idx = row.index.data();
  float *px = row.px.data(), *py = row.py.data(), *pz = row.pz.data(), *nx = row.nx.data(), *ny = row.ny.data(), *nz = row.nz.data();
  float *rc = row.rc.data(), *rs = row.rs.data();
  // Pixel j as entry m; the entry is kept (m advances) only when the pixel is covered.
  auto one_pixel = [&](int j, int m) {
    idx[m] = j;
    px[m] = pos[3 * j], py[m] = pos[3 * j + 1], pz[m] = pos[3 * j + 2];
    nx[m] = nrm[3 * j], ny[m] = nrm[3 * j + 1], nz[m] = nrm[3 * j + 2];
    rc[m] = rot_c[(first + j) & 3], rs[m] = rot_s[(first + j) & 3];
    return id[j] != 0 ? 1 : 0;
  };
  int m = 0, j = 0;
  for (; j + n <= len; j += n) {
    const auto covered = hn::Ne(hn::LoadU(du, id + j), hn::Zero(du));
    if (hn::AllTrue(du, covered)) {
      hn::StoreU(hn::Iota(di, j), di, idx + m);
      VF x, y3, z;
      hn::LoadInterleaved3(d, pos + 3 * j, x, y3, z);
      hn::StoreU(x, d, px + m), hn::StoreU(y3, d, py + m), hn::StoreU(z, d, pz + m);
      hn::LoadInterleaved3(d, nrm + 3 * j, x, y3, z);
      hn::StoreU(x, d, nx + m), hn::StoreU(y3, d, ny + m), hn::StoreU(z, d, nz + m);
      hn::StoreU(hn::LoadU(d, pattern_c + (j & 3)), d, rc + m), hn::StoreU(hn::LoadU(d, pattern_s + (j & 3)), d, rs + m);
      m += n;
    } else if (!hn::AllFalse(du, covered)) {
      for (int k = j; k < j + n; ++k) m += one_pixel(k, m);
    }
  }
  for (; j < len; ++j) m += one_pixel(j, m);
  row.count = m;
  const int end = padded(m);
  for (int k = m; k < end; ++k) {
    idx[k] = 0;
    px[k] = py[k] = 0.0f, pz[k] = -1.0f;
    nx[k] = ny[k] = 0.0f, nz[k] = 1.0f;
    rc[k] = 1.0f, rs[k] = 0.0f;
  }
  return end;
}

// The entries' depth bias: bias_world where it is > 0, else a pixel's footprint at the entry's
// depth times (1 + tan theta_v).
void set_bias(CoveredPixels& row, const GBuffer& g, int end, float bias_world) {
  const DF d;
  if (bias_world > 0) {
    std::fill(row.bias.begin(), row.bias.begin() + end, bias_world);
    return;
  }
  // One pixel's footprint at unit depth: the image plane spans 2 tan(fov/2) over `height` pixels.
  const VF footprint = hn::Set(d, 2.0f * g.camera.tan_half_fov() / static_cast<float>(g.height()));
  const VF one = hn::Set(d, 1.0f), zero = hn::Zero(d), min_cos = hn::Set(d, 0.124f);  // cos 82.9 deg: tan <= 8
  for (int k0 = 0; k0 < end; k0 += static_cast<int>(hn::Lanes(d))) {
    const VF px = hn::Load(d, row.px.data() + k0), py = hn::Load(d, row.py.data() + k0), pz = hn::Load(d, row.pz.data() + k0);
    const VF nx = hn::Load(d, row.nx.data() + k0), ny = hn::Load(d, row.ny.data() + k0), nz = hn::Load(d, row.nz.data() + k0);
    // tan theta_v from N and the unit view direction u = p / |p| (p itself when |p| = 0).
    const VF len = hn::Sqrt(hn::MulAdd(pz, pz, hn::MulAdd(py, py, hn::Mul(px, px))));
    const MF positive = hn::Gt(len, zero);
    const VF ux = hn::IfThenElse(positive, hn::Div(px, len), px), uy = hn::IfThenElse(positive, hn::Div(py, len), py);
    const VF uz = hn::IfThenElse(positive, hn::Div(pz, len), pz);
    const VF cos_v = hn::Max(hn::Abs(hn::MulAdd(nz, uz, hn::MulAdd(ny, uy, hn::Mul(nx, ux)))), min_cos);
    const VF tan_v = hn::Div(hn::Sqrt(hn::NegMulAdd(cos_v, cos_v, one)), cos_v);
    hn::Store(hn::Mul(hn::Mul(footprint, hn::Neg(pz)), hn::Add(one, tan_v)), d, row.bias.data() + k0);
  }
}

// The entries' rotated frames T', B' about their normals.
void rotate_frames(CoveredPixels& row, int end) {
  const DF d;
  const VF one = hn::Set(d, 1.0f), minus_one = hn::Set(d, -1.0f);
  for (int k0 = 0; k0 < end; k0 += static_cast<int>(hn::Lanes(d))) {
    const VF nx = hn::Load(d, row.nx.data() + k0), ny = hn::Load(d, row.ny.data() + k0), nz = hn::Load(d, row.nz.data() + k0);
    // Frame::from_normal (Duff et al. 2017): T = (1 + s nx^2 a, s c, -s nx), B = (c, s + ny^2 a, -ny)
    // with s = sign(nz), a = -1 / (s + nz), c = nx ny a.
    const VF sign = hn::CopySign(one, nz);
    const VF a = hn::Div(minus_one, hn::Add(sign, nz));
    const VF c = hn::Mul(hn::Mul(nx, ny), a);
    const VF ftx = hn::MulAdd(hn::Mul(hn::Mul(sign, nx), nx), a, one), fty = hn::Mul(sign, c), ftz = hn::Neg(hn::Mul(sign, nx));
    const VF fbx = c, fby = hn::MulAdd(hn::Mul(ny, ny), a, sign), fbz = hn::Neg(ny);
    // Rotation by alpha about N (sec. 4.2): T' = cos a T + sin a B, B' = -sin a T + cos a B.
    const VF rc = hn::Load(d, row.rc.data() + k0), rs = hn::Load(d, row.rs.data() + k0);
    hn::Store(hn::MulAdd(fbx, rs, hn::Mul(ftx, rc)), d, row.tx.data() + k0);
    hn::Store(hn::MulAdd(fby, rs, hn::Mul(fty, rc)), d, row.ty.data() + k0);
    hn::Store(hn::MulAdd(fbz, rs, hn::Mul(ftz, rc)), d, row.tz.data() + k0);
    hn::Store(hn::NegMulAdd(ftx, rs, hn::Mul(fbx, rc)), d, row.bx.data() + k0);
    hn::Store(hn::NegMulAdd(fty, rs, hn::Mul(fby, rc)), d, row.by.data() + k0);
    hn::Store(hn::NegMulAdd(ftz, rs, hn::Mul(fbz, rc)), d, row.bz.data() + k0);
  }
}

}  // namespace

void LoadCoveredPixels(CoveredPixels& row, const GBuffer& g, int y, int first, int last, const Rotations16& rotations, float bias_world,
                       bool frame) {
  const auto cap = static_cast<std::size_t>(padded(last - first));
  row.y = y, row.x0 = first;
  for (AlignedVector<float>* v : {&row.px, &row.py, &row.pz, &row.nx, &row.ny, &row.nz, &row.rc, &row.rs, &row.bias}) v->resize(cap);
  if (frame)
    for (AlignedVector<float>* v : {&row.tx, &row.ty, &row.tz, &row.bx, &row.by, &row.bz}) v->resize(cap);
  row.index.resize(cap);
  const int end = load_entries(row, g, y, first, last, rotations);
  set_bias(row, g, end, bias_world);
  if (frame) rotate_frames(row, end);
}

template <bool kTwoLayers>
void CountOpenRaysImpl(const CoveredPixels& row, const DepthPlane& plane, const TestPoints& s, int m, float far_limit, float* open) {
  const DF d;
  const Plane pl(plane);
  const StepOffsets offsets(s, m);
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f), far = hn::Set(d, far_limit), inf = hn::Set(d, kInfinity);
  for (int k0 = 0; k0 < row.count; k0 += static_cast<int>(hn::Lanes(d))) {
    const Entries e(row, k0);
    const VF minus_bias = hn::Neg(e.bias);
    VF count = zero;
    for (int i = 0; i < s.n; ++i) {
      // AT sec. 4: I = prod_j I0(x + w r j/m), the ray is free only if all m test points are.
      MF blocked = hn::MaskFromVec(zero);
      for (int j = 1; j <= m; ++j) {
        const float* o = offsets.at(i, j);
        VF qx, qy, qz;
        e.point(o[0], o[1], o[2], qx, qy, qz);
        // DepthBufferCharacteristic::distance: z* - depth(p), +infinity behind the camera.
        const VI pixel = pl.pixel(qx, qy, qz);
        const VF zs = hn::GatherIndex(d, pl.depth, pixel);
        const VF dist = hn::IfThenElse(hn::Lt(qz, zero), hn::Add(zs, qz), inf);
        // Occluded: behind the surface by more than the bias, and (AT 4.3) less than R behind it;
        // with a second layer also inside the solid behind the surface (not past its end).
        MF occluded = hn::And(hn::Lt(dist, minus_bias), hn::Gt(dist, far));
        if constexpr (kTwoLayers) occluded = hn::And(occluded, pl.in_solid(hn::Neg(qz), zs, gather_where(occluded, pl.second, pixel)));
        blocked = hn::Or(blocked, occluded);
      }
      count = hn::Add(count, hn::IfThenZeroElse(blocked, one));
    }
    hn::Store(count, d, open + k0);
  }
}

template <bool kTwoLayers>
void SumFreePipesImpl(const CoveredPixels& row, const DepthPlane& plane, float half_radius, const TestPoints& disk, float far_limit,
                      float* free) {
  const DF d;
  const Plane pl(plane);
  const VF zero = hn::Zero(d), hr = hn::Set(d, half_radius), lim = hn::Set(d, far_limit), inf = hn::Set(d, kInfinity);
  const VF minus_huge = hn::Set(d, -1e30f);  // below this a distance stands for -infinity (never distant)
  for (int k0 = 0; k0 < row.count; k0 += static_cast<int>(hn::Lanes(d))) {
    // Fig. 4: the tangent sphere's centre c = x + N R/2. Its pipes run along the view axis at depth
    // c_z, so the divide by -c_z and the pixel's rotation fold into affine coefficients of the
    // disk sample (x_i, y_i):  f_x = f_x0 + x_i a_x - y_i b_x,  f_y = f_y0 - x_i a_y - y_i b_y.
    const VF cx = hn::MulAdd(hr, hn::Load(d, row.nx.data() + k0), hn::Load(d, row.px.data() + k0));
    const VF cy = hn::MulAdd(hr, hn::Load(d, row.ny.data() + k0), hn::Load(d, row.py.data() + k0));
    const VF cz = hn::MulAdd(hr, hn::Load(d, row.nz.data() + k0), hn::Load(d, row.pz.data() + k0));
    const VF rc = hn::Load(d, row.rc.data() + k0), rs = hn::Load(d, row.rs.data() + k0), bias = hn::Load(d, row.bias.data() + k0);
    const VF inv = hn::Div(hn::Set(d, -1.0f), cz), kx = hn::Mul(inv, pl.scale_x), ky = hn::Mul(inv, pl.scale_y);
    const VF fx0 = hn::MulAdd(cx, kx, pl.centre_x), fy0 = hn::NegMulAdd(cy, ky, pl.centre_y);
    const VF ax = hn::Mul(rc, kx), bx = hn::Mul(rs, kx), ay = hn::Mul(rs, ky), by = hn::Mul(rc, ky);
    // As ScreenProjection::locate: clamp-to-edge, free only behind the camera.
    const MF valid = hn::Lt(cz, zero);
    VF acc = zero;
    for (int i = 0; i < disk.n; ++i) {
      const float xi = half_radius * disk.x[i], yi = half_radius * disk.y[i];
      const float half_chord = half_radius * disk.z[i];  // (R/2) h_i = z_c - z_entry
      const VF hc = hn::Set(d, half_chord), chord = hn::Set(d, 2.0f * half_chord);  // z_exit - z_entry
      const VF vxi = hn::Set(d, xi), vyi = hn::Set(d, yi);
      const VF fx = hn::NegMulAdd(vyi, bx, hn::MulAdd(vxi, ax, fx0)), fy = hn::NegMulAdd(vyi, by, hn::NegMulAdd(vxi, ay, fy0));
      // Clamp-to-edge as Plane::pixel (behind the camera the pixel is any one: the pipe is free).
      const VI ix = truncate_in_range(hn::Min(hn::Max(fx, zero), pl.max_x));
      const VI iy = truncate_in_range(hn::Min(hn::Max(fy, zero), pl.max_y));
      const VI pixel = hn::Add(hn::Mul(iy, pl.width), ix);
      const VF zs = hn::GatherIndex(d, pl.depth, pixel);
      // DepthBufferCharacteristic::distance z* - z_c, then z* - z_entry = (z* - z_c) + (R/2) h_i.
      const VF to_surface = hn::Add(hn::Add(hn::IfThenElse(valid, hn::Add(zs, cz), inf), hc), bias);
      // Fig. 7: dz = clamp(z* - z_entry, 0, chord): (a) surface inside: z* - z_entry; (b) behind:
      // the chord; (c) in front: 0. A distant foreground surface (AT 4.3) leaves the pipe free.
      VF dz = hn::Min(hn::Max(to_surface, zero), chord);
      if constexpr (kTwoLayers) {
        // The solid in the pipe is [dz, end) and [next, chord) from its entry (depth_layers.h), so
        // the free length is next - max(0, end - dz), both clamped to the pipe.
        const MF reaches = hn::And(valid, hn::Lt(to_surface, chord));  // the solid begins inside the pipe
        const VF s2 = gather_where(reaches, pl.second, pixel);
        const VF from_entry = hn::Add(cz, hc);  // depth z - z_entry = z + c_z + (R/2) h_i
        const VF end = hn::Min(hn::Max(hn::Add(pl.solid_end(zs, s2), from_entry), zero), chord);
        const VF next = hn::Min(hn::Max(hn::Add(Plane::next_solid(s2), from_entry), zero), chord);
        dz = hn::IfThenElse(reaches, hn::Sub(next, hn::Max(hn::Sub(end, dz), zero)), dz);
      }
      const MF distant = hn::And(hn::Lt(to_surface, lim), hn::Gt(to_surface, minus_huge));
      acc = hn::Add(acc, hn::IfThenElse(distant, chord, dz));
    }
    hn::Store(acc, d, free + k0);
  }
}

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
    // also inside the solid behind the surface.
    MF occluded = hn::And(valid, hn::And(hn::Lt(dist, minus_bias), hn::Gt(dist, far)));
    if constexpr (kTwoLayers) occluded = hn::And(occluded, pl.in_solid(hn::Neg(qz), z1, gather_where(occluded, pl.second, pixel)));
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
      out.rgb[at_pixel] = Vec3{wr[k], wg[k], wb[k]}, out.r[at_pixel] = luminance(wr[k], wg[k], wb[k]), out.o[at_pixel] = wo[k];
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

void CountOpenRays(const CoveredPixels& row, const DepthPlane& plane, const TestPoints& s, int m, float far_limit, float* open) {
  if (plane.second)
    CountOpenRaysImpl<true>(row, plane, s, m, far_limit, open);
  else
    CountOpenRaysImpl<false>(row, plane, s, m, far_limit, open);
}

void SumFreePipes(const CoveredPixels& row, const DepthPlane& plane, float half_radius, const TestPoints& disk, float far_limit, float* free) {
  if (plane.second)
    SumFreePipesImpl<true>(row, plane, half_radius, disk, far_limit, free);
  else
    SumFreePipesImpl<false>(row, plane, half_radius, disk, far_limit, free);
}

void InterleaveTransfer(const float* r, const float* g, const float* b, std::size_t n, Vec3* rgb, float* lum) {
  const DF d;
  const std::size_t lanes = hn::Lanes(d);
  const VF kr = hn::Set(d, 0.2126f), kg = hn::Set(d, 0.7152f), kb = hn::Set(d, 0.0722f);
  float* out = &rgb->x;  // Vec3 is three packed floats
  std::size_t k = 0;
  for (; k + lanes <= n; k += lanes) {
    const VF vr = hn::LoadU(d, r + k), vg = hn::LoadU(d, g + k), vb = hn::LoadU(d, b + k);
    hn::StoreInterleaved3(vr, vg, vb, d, out + 3 * k);
    // luminance()'s products and sums in its order: the same bits as the scalar tail.
    hn::StoreU(hn::Add(hn::Add(hn::Mul(kr, vr), hn::Mul(kg, vg)), hn::Mul(kb, vb)), d, lum + k);
  }
  for (; k < n; ++k) {
    const float vr = r[k], vg = g[k], vb = b[k];
    rgb[k] = Vec3{vr, vg, vb};
    lum[k] = luminance(vr, vg, vb);
  }
}

}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ao::simd {

HWY_EXPORT(LoadCoveredPixels);
HWY_EXPORT(InterleaveTransfer);
HWY_EXPORT(CountOpenRays);
HWY_EXPORT(SumFreePipes);
HWY_EXPORT(TransferRays);

void load_covered_pixels(CoveredPixels& row, const GBuffer& g, int y, int x0, int x1, const Rotations16& rotations, float bias_world,
                         bool frame) {
  HWY_DYNAMIC_DISPATCH(LoadCoveredPixels)(row, g, y, x0, x1, rotations, bias_world, frame);
}

void count_open_rays(const CoveredPixels& row, const DepthPlane& plane, const TestPoints& samples, int m, float far_limit, float* open) {
  HWY_DYNAMIC_DISPATCH(CountOpenRays)(row, plane, samples, m, far_limit, open);
}

void sum_free_pipes(const CoveredPixels& row, const DepthPlane& plane, float half_radius, const TestPoints& disk, float far_limit,
                    float* free) {
  HWY_DYNAMIC_DISPATCH(SumFreePipes)(row, plane, half_radius, disk, far_limit, free);
}

void transfer_rays(const CoveredPixels& row, const DepthPlane& plane, const TestPoints& samples, int m, float far_limit,
                   const TransferInputs& in, std::size_t row_base, const TransferOutputs& out) {
  HWY_DYNAMIC_DISPATCH(TransferRays)(row, plane, samples, m, far_limit, in, row_base, out);
}

void interleave_transfer(const float* r, const float* g, const float* b, std::size_t n, Vec3* rgb, float* lum) {
  HWY_DYNAMIC_DISPATCH(InterleaveTransfer)(r, g, b, n, rgb, lum);
}

}  // namespace ao::simd
#endif
