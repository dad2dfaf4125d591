// The ray-traced baker's ray makers (bake/texel_rays_internal.h: make_texel_rays,
// make_hemisphere_rays), compiled once per SIMD target: written as loops over the 16 lanes of a
// batch, which each target's compiler vectorises with its own registers (4, 8 or 16 floats), so a
// portable build makes its rays as fast as one compiled for the CPU. Part of ao::ao (the batch and
// the patch belong to the bakers).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/bake/texel_rays_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <algorithm>
#include <cmath>

#include <hwy/highway.h>

#include "ao/bake/texel_rays_internal.h"

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

void MakeTexelRays(const std::vector<PatchPiece>& patch, const PatchTable& table, const float (&u)[4][16], int count, bool geometric,
                     TexelRayBatch& out) {
  constexpr int W = TexelRayBatch::kWidth;
  using T = PatchTable;
  // Per lane, the piece (sample_patch's: the first whose cumulative area exceeds u2 * total; the
  // cumulative areas are non-decreasing) and its fields, looked up from the texel's table (a
  // permute across a register for each field), so that the arithmetic below reads only lane
  // arrays and vectorises.
  alignas(64) float lane[T::kFields][W];
  alignas(64) float su[W], target[W];
  alignas(64) int piece[W];
  const float total = patch.back().cdf;
  for (int k = 0; k < W; ++k) target[k] = u[2][k] * total, piece[k] = 0;
  for (std::size_t j = 0; j + 1 < patch.size(); ++j) {
    const float cj = patch[j].cdf;
    for (int k = 0; k < W; ++k) piece[k] += cj <= target[k] ? 1 : 0;
  }
  if (patch.size() <= T::kMaxPieces) {
    for (int q = 0; q < T::kFields; ++q)
      for (int k = 0; k < W; ++k) lane[q][k] = table.f[q][piece[k]];
  } else {
    for (int k = 0; k < W; ++k) {
      float v[T::kFields];
      table.piece_fields(patch, static_cast<std::size_t>(piece[k]), v);
      for (int q = 0; q < T::kFields; ++q) lane[q][k] = v[q];
    }
  }
  constexpr int kP = T::kP, kN = T::kN, kNg = T::kNg, kOff = T::kOff, kLo = T::kLo, kInvSpan = T::kInvSpan;
  for (int k = 0; k < W; ++k) su[k] = std::min(std::max((target[k] - lane[kLo][k]) * lane[kInvSpan][k], 0.0f), 1.0f);
  for (int k = 0; k < W; ++k) {
    // The point: corner weights (1 - r, r (1 - t), r t), r = sqrt(s), as sample_patch.
    const float r = std::sqrt(su[k]);
    const float w0 = 1.0f - r, w1 = r * (1.0f - u[3][k]), w2 = r * u[3][k];
    float pos[3], nrm[3];
    for (int a = 0; a < 3; ++a) {
      pos[a] = lane[kP + a][k] * w0 + lane[kP + 3 + a][k] * w1 + lane[kP + 6 + a][k] * w2;
      nrm[a] = lane[kN + a][k] * w0 + lane[kN + 3 + a][k] * w1 + lane[kN + 6 + a][k] * w2;
    }
    // The unit normal (PatchSample::normal: the face normal where the vertex normals cancel).
    const float len = std::sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    const bool face = geometric || !(len > 1e-6f);
    const float inv = 1.0f / std::max(len, 1e-6f);
    const float nx = face ? lane[kNg][k] : nrm[0] * inv, ny = face ? lane[kNg + 1][k] : nrm[1] * inv, nz = face ? lane[kNg + 2][k] : nrm[2] * inv;
    // Frame::from_normal (Duff et al. 2017).
    const float sign = std::copysign(1.0f, nz);
    const float fa = -1.0f / (sign + nz);
    const float fc = nx * ny * fa;
    const float tx = 1.0f + sign * nx * nx * fa, ty = sign * fc, tz = -sign * nx;
    const float bx = fc, by = sign + ny * ny * fa, bz = -ny;
    float lx, ly, lz;
    concentric_hemisphere(u[0][k], u[1][k], lx, ly, lz);
    const float dx = tx * lx + bx * ly + nx * lz, dy = ty * lx + by * ly + ny * lz, dz = tz * lx + bz * ly + nz * lz;
    // Below the face: occluded by the surface itself (mu = 0), no ray.
    const bool above = dx * lane[kNg][k] + dy * lane[kNg + 1][k] + dz * lane[kNg + 2][k] > 0;
    out.valid[k] = k < count && above ? -1 : 0;
    out.ox[k] = pos[0] + lane[kNg][k] * lane[kOff][k];
    out.oy[k] = pos[1] + lane[kNg + 1][k] * lane[kOff][k];
    out.oz[k] = pos[2] + lane[kNg + 2][k] * lane[kOff][k];
    out.dx[k] = dx, out.dy[k] = dy, out.dz[k] = dz;
  }
}

void MakeHemisphereRays(Vec3 origin, Vec3 n, Vec3 ng, const float (&u)[4][16], int count, TexelRayBatch& out) {
  const Frame f = Frame::from_normal(n);
  for (int k = 0; k < TexelRayBatch::kWidth; ++k) {
    float lx, ly, lz;
    concentric_hemisphere(u[0][k], u[1][k], lx, ly, lz);
    const float dx = f.t.x * lx + f.b.x * ly + f.n.x * lz, dy = f.t.y * lx + f.b.y * ly + f.n.y * lz, dz = f.t.z * lx + f.b.z * ly + f.n.z * lz;
    out.valid[k] = k < count && dx * ng.x + dy * ng.y + dz * ng.z > 0 ? -1 : 0;
    out.ox[k] = origin.x, out.oy[k] = origin.y, out.oz[k] = origin.z;
    out.dx[k] = dx, out.dy[k] = dy, out.dz[k] = dz;
  }
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
