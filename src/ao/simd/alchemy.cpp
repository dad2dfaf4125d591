// Kernel of Alchemy AO's estimator, eq. 10 (alchemy_internal.h; methods/alchemy.cpp for the method
// and its constants), compiled once per SIMD target: a vector of a row's pixels runs all s samples
// with its sums in registers, one depth gather per sample. Multiply-adds are written out (MulAdd);
// this file is compiled without contraction, so targets with FMA agree bit for bit.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/simd/alchemy.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <algorithm>
#include <bit>
#include <limits>

#include <hwy/highway.h>

#include "ao/core/error.h"
#include "ao/core/math.h"
#include "ao/core/sampling.h"
#include "ao/simd/aligned_internal.h"
#include "ao/simd/alchemy_internal.h"
#include "ao/simd/vec_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

namespace {

// Pixel coordinates are offset by this so they stay positive and truncation acts as floor (the
// disk's screen radius is capped below it).
constexpr float kCoordOffset = 65536.0f;
constexpr std::uint32_t kRotationMask = 1023;  // the rotation table holds 1024 angles

// hash32 and hash_combine of core/sampling.h, lane-wise.
HWY_INLINE VU hash32(VU x) {
  const DU du;
  x = hn::Xor(x, hn::ShiftRight<16>(x));
  x = hn::Mul(x, hn::Set(du, 0x7feb352du));
  x = hn::Xor(x, hn::ShiftRight<15>(x));
  x = hn::Mul(x, hn::Set(du, 0x846ca68bu));
  return hn::Xor(x, hn::ShiftRight<16>(x));
}
HWY_INLINE VU hash_combine(VU seed, VU v) {
  const DU du;
  return hash32(hn::Xor(seed, hn::Add(hn::Add(hn::Add(v, hn::Set(du, 0x9e3779b9u)), hn::ShiftLeft<6>(seed)), hn::ShiftRight<2>(seed))));
}

// sqrt(x) for x in [0, 1] by the reciprocal square root bit trick and two Newton steps, relative
// error < 5e-6 (far below a pixel at any disk radius): the estimator's own square root.
HWY_INLINE VF sqrt_unit(VF x) {
  const DF d;
  const DU du;
  const VF half = hn::Set(d, 0.5f), three_halves = hn::Set(d, 1.5f);
  VF r = hn::BitCast(d, hn::Sub(hn::Set(du, 0x5f3759dfu), hn::ShiftRight<1>(hn::BitCast(du, x))));
  const VF hx = hn::Mul(half, x);
  r = hn::Mul(r, hn::NegMulAdd(hn::Mul(hx, r), r, three_halves));
  r = hn::Mul(r, hn::NegMulAdd(hn::Mul(hx, r), r, three_halves));
  return hn::Mul(x, r);
}

HWY_INLINE float sqrt_unit(float x) {
  float r = std::bit_cast<float>(0x5f3759dfu - (std::bit_cast<std::uint32_t>(x) >> 1));
  r = r * (1.5f - 0.5f * x * r * r);
  r = r * (1.5f - 0.5f * x * r * r);
  return x * r;
}

// The same estimator one pixel at a time with 64-bit pixel indices, for images of 2^31 pixels
// and more (whose indices do not fit the gathers' 32-bit lanes).
void alchemy_row_wide(const AlchemyInputs& in, int y, int x0, int x1, float* out) {
  const std::size_t w = static_cast<std::size_t>(in.width);
  const float r2 = in.radius * in.radius, inv_s = 1.0f / static_cast<float>(in.samples);
  for (int x = x0; x < x1; ++x) {
    const std::size_t at = static_cast<std::size_t>(y) * w + static_cast<std::size_t>(x);
    if (!in.object_id[at]) {
      out[x - x0] = 1.0f;
      continue;
    }
    const float dc = in.depth[at];
    const float cx = dc * (in.ray_ax * (static_cast<float>(x) + 0.5f) + in.ray_bx), cy = dc * (in.ray_ay * (static_cast<float>(y) + 0.5f) + in.ray_by),
                cz = -dc;
    const float nx = in.normal[3 * at], ny = in.normal[3 * at + 1], nz = in.normal[3 * at + 2];
    const float radius_px = std::min(in.max_pixel_radius, in.radius * in.px_per_unit / dc);
    const std::uint32_t hs = pixel_seed(in.seed, x, y);
    const float jitter = to_unit_float(hs);
    const std::uint32_t ri = ao::hash32(hs) & kRotationMask;
    float sum = 0;
    for (int i = 0; i < in.samples; ++i) {
      const float rho = radius_px * sqrt_unit((static_cast<float>(i) + jitter) * inv_s);
      const float dx = rho * (in.rot_c[ri] * in.ux[i] - in.rot_s[ri] * in.uy[i]), dy = rho * (in.rot_s[ri] * in.ux[i] + in.rot_c[ri] * in.uy[i]);
      const int ix = std::clamp(static_cast<int>(static_cast<float>(x) + 0.5f + kCoordOffset + dx) - static_cast<int>(kCoordOffset), 0, in.width - 1);
      const int iy = std::clamp(static_cast<int>(static_cast<float>(y) + 0.5f + kCoordOffset + dy) - static_cast<int>(kCoordOffset), 0, in.height - 1);
      const float dp = in.depth[static_cast<std::size_t>(iy) * w + static_cast<std::size_t>(ix)];
      const float vx = dp * (in.ray_ax * (static_cast<float>(ix) + 0.5f) + in.ray_bx) - cx;
      const float vy = dp * (in.ray_ay * (static_cast<float>(iy) + 0.5f) + in.ray_by) - cy, vz = -dp - cz;
      const float vv = vx * vx + vy * vy + vz * vz, vn = vx * nx + vy * ny + vz * nz + cz * in.beta;
      sum += vv < r2 && vn > 0.0f ? vn / (vv + in.epsilon) : 0.0f;
    }
    out[x - x0] = std::max(0.0f, 1.0f - in.scale * sum);
  }
}

}  // namespace

void AlchemyRow(const AlchemyInputs& in, int y, int x0, int x1, float* out) {
  if (static_cast<std::size_t>(in.width) * static_cast<std::size_t>(in.height) >= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    return alchemy_row_wide(in, y, x0, x1, out);
  const DF d;
  const DI di;
  const DU du;
  const int lanes = static_cast<int>(hn::Lanes(d)), n = x1 - x0, w = in.width;
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f), half = hn::Set(d, 0.5f);
  const VF ax = hn::Set(d, in.ray_ax), bx = hn::Set(d, in.ray_bx), ay = hn::Set(d, in.ray_ay), by = hn::Set(d, in.ray_by);
  const VF r2 = hn::Set(d, in.radius * in.radius), eps = hn::Set(d, in.epsilon), beta = hn::Set(d, in.beta), scale = hn::Set(d, in.scale);
  const VF inv_s = hn::Set(d, 1.0f / static_cast<float>(in.samples));
  const VF offset = hn::Set(d, kCoordOffset);
  const VI ioffset = hn::Set(di, static_cast<int>(kCoordOffset)), izero = hn::Zero(di), max_ix = hn::Set(di, w - 1),
           max_iy = hn::Set(di, in.height - 1), width = hn::Set(di, w);
  // Per pixel of the whole image the seed's hash is the same: pixel_seed = hash_combine(hash_combine(hash32(seed), x), y).
  const VU seed_hash = hn::Set(du, ao::hash32(in.seed)), row_y = hn::Set(du, static_cast<std::uint32_t>(y));
  const VF fy = hn::Set(d, static_cast<float>(y) + 0.5f);
  // The row's per-pixel values, structure of arrays: the sample loop below runs sample by sample
  // across the row (the gathers of a sample's pixel vectors are independent and close in the image).
  AO_ASSERT(n <= kMaxAlchemySegment);
  HWY_ALIGN float cx[kMaxAlchemySegment], cy[kMaxAlchemySegment], cz[kMaxAlchemySegment], nx[kMaxAlchemySegment], ny[kMaxAlchemySegment],
      nz[kMaxAlchemySegment], bias[kMaxAlchemySegment], radius_px[kMaxAlchemySegment], jitter[kMaxAlchemySegment], rc[kMaxAlchemySegment],
      rs[kMaxAlchemySegment], fx0[kMaxAlchemySegment], sum[kMaxAlchemySegment], cov[kMaxAlchemySegment];
  const VI lane = hn::Iota(di, 0);  // made once: Highway builds it through memory
  const int end = (n + lanes - 1) / lanes * lanes;
  const std::size_t row = static_cast<std::size_t>(y) * w + x0;
  for (int j0 = 0; j0 < end; j0 += lanes) {
    const VI j = hn::Add(lane, hn::Set(di, j0));
    const VI x = hn::Add(hn::Set(di, x0), j);
    // The row's depths, ids and normals: contiguous loads; the last vector, past the segment,
    // gathers its last pixel again (valid reads; those lanes' results are not written).
    VF depth, nx_v, ny_v, nz_v;
    MF covered;
    if (j0 + lanes <= n) {
      depth = hn::LoadU(d, in.depth + row + j0);
      covered = hn::RebindMask(d, hn::Not(hn::Eq(hn::LoadU(du, in.object_id + row + j0), hn::Zero(du))));
      hn::LoadInterleaved3(d, in.normal + 3 * (row + j0), nx_v, ny_v, nz_v);
    } else {
      const VI pixel = hn::Add(hn::Set(di, static_cast<int>(row)), hn::Min(j, hn::Set(di, n - 1)));
      depth = hn::GatherIndex(d, in.depth, pixel);
      covered = hn::RebindMask(d, hn::Not(hn::Eq(hn::GatherIndex(du, in.object_id, pixel), hn::Zero(du))));
      const VI p3 = hn::Mul(pixel, hn::Set(di, 3));
      nx_v = hn::GatherIndex(d, in.normal, p3), ny_v = hn::GatherIndex(d, in.normal + 1, p3), nz_v = hn::GatherIndex(d, in.normal + 2, p3);
    }
    // C from the depth buffer, as its samples (so C and its samples agree exactly on a plane);
    // background: C = 0, its result is overwritten.
    const VF dc = hn::IfThenElseZero(covered, depth);
    const VF fx = hn::Add(hn::ConvertTo(d, x), half);
    const VF vcz = hn::Neg(dc);
    hn::Store(hn::Mul(dc, hn::MulAdd(ax, fx, bx)), d, cx + j0), hn::Store(hn::Mul(dc, hn::MulAdd(ay, fy, by)), d, cy + j0), hn::Store(vcz, d, cz + j0);
    hn::Store(nx_v, d, nx + j0), hn::Store(ny_v, d, ny + j0), hn::Store(nz_v, d, nz + j0);
    // Eq. 10's z_C beta: z_C < 0, so this lowers v.n and drops samples nearly in the tangent plane
    // (self-occlusion from imprecise normals and positions), more so far away.
    hn::Store(hn::Mul(vcz, beta), d, bias + j0);
    // Screen radius of the world disk; background has depth +inf, so radius 0.
    hn::Store(hn::Min(hn::Set(d, in.max_pixel_radius), hn::Div(hn::Set(d, in.radius * in.px_per_unit), depth)), d, radius_px + j0);
    // The pixel's jitter and rotation of the pattern, from its seed.
    const VU hs = hash_combine(hash_combine(seed_hash, hn::BitCast(du, x)), row_y);
    hn::Store(hn::Mul(hn::ConvertTo(d, hn::BitCast(di, hn::ShiftRight<8>(hs))), hn::Set(d, 0x1.0p-24f)), d, jitter + j0);
    const VI ri = hn::BitCast(di, hn::And(hash32(hs), hn::Set(du, kRotationMask)));
    hn::Store(hn::GatherIndex(d, in.rot_c, ri), d, rc + j0), hn::Store(hn::GatherIndex(d, in.rot_s, ri), d, rs + j0);
    hn::Store(hn::Add(fx, offset), d, fx0 + j0);
    hn::Store(zero, d, sum + j0);
    hn::Store(hn::IfThenElseZero(covered, one), d, cov + j0);
  }
  const VF fy0 = hn::Add(fy, offset);
  for (int i = 0; i < in.samples; ++i) {
    // Sample i lies in the i-th of s equal-area annuli (radius sqrt((i + jitter) / s)) at angle
    // i * golden angle + the pixel's rotation: stratified, and uniform on the disk.
    const VF pux = hn::Set(d, in.ux[i]), puy = hn::Set(d, in.uy[i]), stratum = hn::Set(d, static_cast<float>(i));
    for (int j0 = 0; j0 < end; j0 += lanes) {
      const VF vrc = hn::Load(d, rc + j0), vrs = hn::Load(d, rs + j0);
      const VF rho = hn::Mul(hn::Load(d, radius_px + j0), sqrt_unit(hn::Mul(hn::Add(stratum, hn::Load(d, jitter + j0)), inv_s)));
      const VF dx = hn::Mul(rho, hn::NegMulAdd(vrs, puy, hn::Mul(vrc, pux))), dy = hn::Mul(rho, hn::MulAdd(vrc, puy, hn::Mul(vrs, pux)));
      // +kCoordOffset keeps the coordinate positive, so truncation is floor. Clamp-to-edge: a
      // sample beyond the frame reads the nearest border pixel (the surfaces at the edge go on
      // beyond it) rather than counting as empty space.
      const VI ix = hn::Min(hn::Max(hn::Sub(truncate_in_range(hn::Add(hn::Load(d, fx0 + j0), dx)), ioffset), izero), max_ix);
      const VI iy = hn::Min(hn::Max(hn::Sub(truncate_in_range(hn::Add(fy0, dy)), ioffset), izero), max_iy);
      const VF dp = hn::GatherIndex(d, in.depth, hn::Add(hn::Mul(iy, width), ix));
      const VF vx = hn::Sub(hn::Mul(dp, hn::MulAdd(ax, hn::Add(hn::ConvertTo(d, ix), half), bx)), hn::Load(d, cx + j0));
      const VF vy = hn::Sub(hn::Mul(dp, hn::MulAdd(ay, hn::Add(hn::ConvertTo(d, iy), half), by)), hn::Load(d, cy + j0));
      const VF vz = hn::Sub(hn::Neg(dp), hn::Load(d, cz + j0));
      const VF vv = hn::MulAdd(vz, vz, hn::MulAdd(vy, vy, hn::Mul(vx, vx)));
      const VF vn = hn::Add(hn::MulAdd(vz, hn::Load(d, nz + j0), hn::MulAdd(vy, hn::Load(d, ny + j0), hn::Mul(vx, hn::Load(d, nx + j0)))),
                            hn::Load(d, bias + j0));
      // Background samples (depth +inf, so vv is inf or NaN and fails vv < r^2) contribute
      // nothing: the paper's assumption that unseen space is empty. vv < r^2 is eq. 9's H.
      const MF use = hn::And(hn::Lt(vv, r2), hn::Gt(vn, zero));
      hn::Store(hn::Add(hn::Load(d, sum + j0), hn::IfThenElseZero(use, hn::Div(vn, hn::Add(vv, eps)))), d, sum + j0);
    }
  }
  HWY_ALIGN float v[kMaxLanes];
  for (int j0 = 0; j0 < n; j0 += lanes) {
    const VF a = hn::Max(hn::NegMulAdd(scale, hn::Load(d, sum + j0), one), zero);  // eq. 10 before ^k
    hn::Store(hn::IfThenElse(hn::Gt(hn::Load(d, cov + j0), zero), a, one), d, v);
    for (int k = 0; k < std::min(lanes, n - j0); ++k) out[j0 + k] = v[k];
  }
}

}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ao::simd {

HWY_EXPORT(AlchemyRow);

void alchemy_row(const AlchemyInputs& in, int y, int x0, int x1, float* v) { HWY_DYNAMIC_DISPATCH(AlchemyRow)(in, y, x0, x1, v); }

}  // namespace ao::simd
#endif
