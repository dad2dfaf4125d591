// SPDX-License-Identifier: Apache-2.0
// The screen-space methods' row loader (screen_space_kernel_internal.h: load_covered_pixels),
// compiled once per SIMD target: a row's covered pixels compacted into the lanes the containment,
// volumetric and transfer kernels (each in its method's folder) run their samples across.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/methods/screen_space_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <algorithm>
#include <cstring>

#include <hwy/highway.h>

#include "ao/methods/screen_space_kernel_internal.h"
#include "ao/methods/screen_space_shared.h"
#include "ao/simd/vec_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

namespace {

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
  const VF one = hn::Set(d, 1.0f), zero = hn::Zero(d), min_cos = hn::Set(d, shared::kMinViewCosine);
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

}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ao::simd {

HWY_EXPORT(LoadCoveredPixels);

void load_covered_pixels(CoveredPixels& row, const GBuffer& g, int y, int x0, int x1, const Rotations16& rotations, float bias_world,
                         bool frame) {
  HWY_DYNAMIC_DISPATCH(LoadCoveredPixels)(row, g, y, x0, x1, rotations, bias_world, frame);
}

}  // namespace ao::simd
#endif
