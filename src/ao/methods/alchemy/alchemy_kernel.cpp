// SPDX-License-Identifier: Apache-2.0
// Kernel of Alchemy AO's estimator, eq. 10 (alchemy_internal.h; methods/alchemy.cpp for the method
// and its constants), compiled once per SIMD target: a vector of a row's pixels runs all s samples
// with its sums in registers, one depth gather per sample. Multiply-adds are written out (MulAdd);
// this file is compiled without contraction, so targets with FMA agree bit for bit.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/methods/alchemy/alchemy_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <algorithm>
#include <bit>
#include <limits>

#include <hwy/highway.h>

#include "ao/core/error.h"
#include "ao/core/math.h"
#include "ao/core/sampling.h"
#include "ao/simd/aligned_internal.h"
#include "ao/methods/alchemy/alchemy_kernel_internal.h"
#include "ao/simd/vec_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

namespace {

// Pixel coordinates are offset by this so they stay positive and truncation acts as floor (the
// disk's screen radius is capped below it).
constexpr float kCoordOffset = shared::kAlchemyCoordOffset;
constexpr std::uint32_t kRotationMask = 1023;  // the rotation table holds 1024 angles

// hash32 and hash_combine of core/sampling.h, lane-wise.
HWY_INLINE VU hash32(VU x) {
  const DU du;
  x = hn::Xor(x, hn::ShiftRight<16>(x));
  x = hn::Mul(x, hn::Set(du, shared::kHashMultiplier1));
  x = hn::Xor(x, hn::ShiftRight<15>(x));
  x = hn::Mul(x, hn::Set(du, shared::kHashMultiplier2));
  return hn::Xor(x, hn::ShiftRight<16>(x));
}
HWY_INLINE VU hash_combine(VU seed, VU v) {
  const DU du;
  return hash32(hn::Xor(seed, hn::Add(hn::Add(hn::Add(v, hn::Set(du, shared::kHashGolden)), hn::ShiftLeft<6>(seed)), hn::ShiftRight<2>(seed))));
}

// sqrt(x) for x in [0, 1] by the reciprocal square root bit trick and two Newton steps, relative
// error < 5e-6 (far below a pixel at any disk radius): the estimator's own square root.
HWY_INLINE VF sqrt_unit(VF x) {
  const DF d;
  const DU du;
  const VF half = hn::Set(d, 0.5f), three_halves = hn::Set(d, 1.5f);
  VF r = hn::BitCast(d, hn::Sub(hn::Set(du, shared::kInvSqrtMagic), hn::ShiftRight<1>(hn::BitCast(du, x))));
  const VF hx = hn::Mul(half, x);
  r = hn::Mul(r, hn::NegMulAdd(hn::Mul(hx, r), r, three_halves));
  r = hn::Mul(r, hn::NegMulAdd(hn::Mul(hx, r), r, three_halves));
  return hn::Mul(x, r);
}

HWY_INLINE float sqrt_unit(float x) {
  float r = std::bit_cast<float>(shared::kInvSqrtMagic - (std::bit_cast<std::uint32_t>(x) >> 1));
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
      const std::size_t tap = static_cast<std::size_t>(iy) * w + static_cast<std::size_t>(ix);
      const float rx = in.ray_ax * (static_cast<float>(ix) + 0.5f) + in.ray_bx, ry = in.ray_ay * (static_cast<float>(iy) + 0.5f) + in.ray_by;
      const auto term = [&](float dp) {
        const float vx = dp * rx - cx, vy = dp * ry - cy, vz = -dp - cz;
        const float vv = vx * vx + vy * vy + vz * vz, vn = vx * nx + vy * ny + vz * nz + cz * in.beta;
        return vv < r2 && vn > 0.0f ? vn / (vv + in.epsilon) : 0.0f;
      };
      sum += in.second ? std::max(term(in.depth[tap]), term(std::abs(in.second[tap]))) : term(in.depth[tap]);
    }
    out[x - x0] = std::max(0.0f, 1.0f - in.scale * sum);
  }
}

// A row segment's per-pixel values, structure of arrays: the sample loop runs sample by sample
// across the row (the gathers of a sample's pixel vectors are independent and close in the image).
struct Row {
  static constexpr int kN = kMaxAlchemySegment;
  HWY_ALIGN float cx[kN], cy[kN], cz[kN], nx[kN], ny[kN], nz[kN], bias[kN], radius_px[kN], jitter[kN], rc[kN], rs[kN], fx0[kN], sum[kN],
      cov[kN];
};

// The row's depths, ids and normals at pixels row_start + j0 + lane: contiguous loads; the last
// vector, past the segment of n pixels, gathers its last pixel again (valid reads; those lanes'
// results are not written).
HWY_INLINE void load_pixels(const AlchemyInputs& in, std::size_t row_start, int j0, int n, VI j, VF& depth, MF& covered, VF& nx, VF& ny,
                            VF& nz) {
  const DF d;
  const DI di;
  const DU du;
  if (j0 + static_cast<int>(hn::Lanes(d)) <= n) {
    depth = hn::LoadU(d, in.depth + row_start + j0);
    covered = hn::RebindMask(d, hn::Not(hn::Eq(hn::LoadU(du, in.object_id + row_start + j0), hn::Zero(du))));
    hn::LoadInterleaved3(d, in.normal + 3 * (row_start + j0), nx, ny, nz);
  } else {
    const VI pixel = hn::Add(hn::Set(di, static_cast<int>(row_start)), hn::Min(j, hn::Set(di, n - 1)));
    depth = hn::GatherIndex(d, in.depth, pixel);
    covered = hn::RebindMask(d, hn::Not(hn::Eq(hn::GatherIndex(du, in.object_id, pixel), hn::Zero(du))));
    const VI p3 = hn::Mul(pixel, hn::Set(di, 3));
    nx = hn::GatherIndex(d, in.normal, p3), ny = hn::GatherIndex(d, in.normal + 1, p3), nz = hn::GatherIndex(d, in.normal + 2, p3);
  }
}

// Each pixel's C, normal, bias, screen radius, jitter and rotation for the segment [x0, x0 + n)
// of row y, whole vectors up to `end`.
HWY_INLINE void prepare_row(const AlchemyInputs& in, int y, int x0, int n, int end, Row& r) {
  const DF d;
  const DI di;
  const DU du;
  const int lanes = static_cast<int>(hn::Lanes(d));
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f), half = hn::Set(d, 0.5f), offset = hn::Set(d, kCoordOffset);
  const VF ax = hn::Set(d, in.ray_ax), bx = hn::Set(d, in.ray_bx), ay = hn::Set(d, in.ray_ay), by = hn::Set(d, in.ray_by);
  const VF beta = hn::Set(d, in.beta), fy = hn::Set(d, static_cast<float>(y) + 0.5f);
  // Per pixel of the whole image the seed's hash is the same: pixel_seed = hash_combine(hash_combine(hash32(seed), x), y).
  const VU seed_hash = hn::Set(du, ao::hash32(in.seed)), row_y = hn::Set(du, static_cast<std::uint32_t>(y));
  const VI lane = hn::Iota(di, 0);  // made once: Highway builds it through memory
  const std::size_t row_start = static_cast<std::size_t>(y) * in.width + x0;
  for (int j0 = 0; j0 < end; j0 += lanes) {
    const VI j = hn::Add(lane, hn::Set(di, j0));
    const VI x = hn::Add(hn::Set(di, x0), j);
    VF depth, nx, ny, nz;
    MF covered;
    load_pixels(in, row_start, j0, n, j, depth, covered, nx, ny, nz);
    // C from the depth buffer, as its samples (so C and its samples agree exactly on a plane);
    // background: C = 0, its result is overwritten.
    const VF dc = hn::IfThenElseZero(covered, depth);
    const VF fx = hn::Add(hn::ConvertTo(d, x), half);
    const VF vcz = hn::Neg(dc);
    hn::Store(hn::Mul(dc, hn::MulAdd(ax, fx, bx)), d, r.cx + j0), hn::Store(hn::Mul(dc, hn::MulAdd(ay, fy, by)), d, r.cy + j0);
    hn::Store(vcz, d, r.cz + j0);
    hn::Store(nx, d, r.nx + j0), hn::Store(ny, d, r.ny + j0), hn::Store(nz, d, r.nz + j0);
    // Eq. 10's z_C beta: z_C < 0, so this lowers v.n and drops samples nearly in the tangent plane
    // (self-occlusion from imprecise normals and positions), more so far away.
    hn::Store(hn::Mul(vcz, beta), d, r.bias + j0);
    // Screen radius of the world disk; background has depth +inf, so radius 0.
    hn::Store(hn::Min(hn::Set(d, in.max_pixel_radius), hn::Div(hn::Set(d, in.radius * in.px_per_unit), depth)), d, r.radius_px + j0);
    // The pixel's jitter and rotation of the pattern, from its seed.
    const VU hs = hash_combine(hash_combine(seed_hash, hn::BitCast(du, x)), row_y);
    hn::Store(hn::Mul(hn::ConvertTo(d, hn::BitCast(di, hn::ShiftRight<8>(hs))), hn::Set(d, 0x1.0p-24f)), d, r.jitter + j0);
    const VI ri = hn::BitCast(di, hn::And(hash32(hs), hn::Set(du, kRotationMask)));
    hn::Store(hn::GatherIndex(d, in.rot_c, ri), d, r.rc + j0), hn::Store(hn::GatherIndex(d, in.rot_s, ri), d, r.rs + j0);
    hn::Store(hn::Add(fx, offset), d, r.fx0 + j0);
    hn::Store(zero, d, r.sum + j0);
    hn::Store(hn::IfThenElseZero(covered, one), d, r.cov + j0);
  }
}

// Eq. 10's sum over the s samples for every pixel of the prepared row (whole vectors up to `end`);
// with kTwoLayers each tap counts the larger term of its two points (AlchemyInputs::second).
template <bool kTwoLayers>
HWY_INLINE void add_samples(const AlchemyInputs& in, int y, int end, Row& r) {
  const DF d;
  const DI di;
  const int lanes = static_cast<int>(hn::Lanes(d));
  const VF zero = hn::Zero(d), half = hn::Set(d, 0.5f);
  const VF ax = hn::Set(d, in.ray_ax), bx = hn::Set(d, in.ray_bx), ay = hn::Set(d, in.ray_ay), by = hn::Set(d, in.ray_by);
  const VF r2 = hn::Set(d, in.radius * in.radius), eps = hn::Set(d, in.epsilon), inv_s = hn::Set(d, 1.0f / static_cast<float>(in.samples));
  const VI ioffset = hn::Set(di, static_cast<int>(kCoordOffset)), izero = hn::Zero(di), max_ix = hn::Set(di, in.width - 1),
           max_iy = hn::Set(di, in.height - 1), width = hn::Set(di, in.width);
  const VF fy0 = hn::Add(hn::Set(d, static_cast<float>(y) + 0.5f), hn::Set(d, kCoordOffset));
  for (int i = 0; i < in.samples; ++i) {
    // Sample i lies in the i-th of s equal-area annuli (radius sqrt((i + jitter) / s)) at angle
    // i * golden angle + the pixel's rotation: stratified, and uniform on the disk.
    const VF pux = hn::Set(d, in.ux[i]), puy = hn::Set(d, in.uy[i]), stratum = hn::Set(d, static_cast<float>(i));
    for (int j0 = 0; j0 < end; j0 += lanes) {
      const VF vrc = hn::Load(d, r.rc + j0), vrs = hn::Load(d, r.rs + j0);
      const VF rho = hn::Mul(hn::Load(d, r.radius_px + j0), sqrt_unit(hn::Mul(hn::Add(stratum, hn::Load(d, r.jitter + j0)), inv_s)));
      const VF dx = hn::Mul(rho, hn::NegMulAdd(vrs, puy, hn::Mul(vrc, pux))), dy = hn::Mul(rho, hn::MulAdd(vrc, puy, hn::Mul(vrs, pux)));
      // +kCoordOffset keeps the coordinate positive, so truncation is floor. Clamp-to-edge: a
      // sample beyond the frame reads the nearest border pixel (the surfaces at the edge go on
      // beyond it) rather than counting as empty space.
      const VI ix = hn::Min(hn::Max(hn::Sub(truncate_in_range(hn::Add(hn::Load(d, r.fx0 + j0), dx)), ioffset), izero), max_ix);
      const VI iy = hn::Min(hn::Max(hn::Sub(truncate_in_range(hn::Add(fy0, dy)), ioffset), izero), max_iy);
      const VI tap = hn::Add(hn::Mul(iy, width), ix);
      const VF rx = hn::MulAdd(ax, hn::Add(hn::ConvertTo(d, ix), half), bx), ry = hn::MulAdd(ay, hn::Add(hn::ConvertTo(d, iy), half), by);
      // Eq. 10's term of the point at depth dp on the tap pixel's ray.
      const auto term = [&](VF dp) {
        const VF vx = hn::Sub(hn::Mul(dp, rx), hn::Load(d, r.cx + j0));
        const VF vy = hn::Sub(hn::Mul(dp, ry), hn::Load(d, r.cy + j0));
        const VF vz = hn::Sub(hn::Neg(dp), hn::Load(d, r.cz + j0));
        const VF vv = hn::MulAdd(vz, vz, hn::MulAdd(vy, vy, hn::Mul(vx, vx)));
        const VF vn = hn::Add(hn::MulAdd(vz, hn::Load(d, r.nz + j0), hn::MulAdd(vy, hn::Load(d, r.ny + j0), hn::Mul(vx, hn::Load(d, r.nx + j0)))),
                              hn::Load(d, r.bias + j0));
        // Background samples (depth +inf, so vv is inf or NaN and fails vv < r^2) contribute
        // nothing: the paper's assumption that unseen space is empty. vv < r^2 is eq. 9's H.
        const MF use = hn::And(hn::Lt(vv, r2), hn::Gt(vn, zero));
        return hn::IfThenElseZero(use, hn::Div(vn, hn::Add(vv, eps)));
      };
      VF t = term(hn::GatherIndex(d, in.depth, tap));
      if constexpr (kTwoLayers) t = hn::Max(t, term(hn::Abs(hn::GatherIndex(d, in.second, tap))));
      hn::Store(hn::Add(hn::Load(d, r.sum + j0), t), d, r.sum + j0);
    }
  }
}

}  // namespace

void AlchemyRow(const AlchemyInputs& in, int y, int x0, int x1, float* out) {
  if (static_cast<std::size_t>(in.width) * static_cast<std::size_t>(in.height) >= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    return alchemy_row_wide(in, y, x0, x1, out);
  const DF d;
  const int lanes = static_cast<int>(hn::Lanes(d)), n = x1 - x0;
  AO_ASSERT(n <= kMaxAlchemySegment);
  const int end = (n + lanes - 1) / lanes * lanes;
  Row r;
  prepare_row(in, y, x0, n, end, r);
  if (in.second)
    add_samples<true>(in, y, end, r);
  else
    add_samples<false>(in, y, end, r);
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f), scale = hn::Set(d, in.scale);
  HWY_ALIGN float v[kMaxLanes];
  for (int j0 = 0; j0 < n; j0 += lanes) {
    const VF a = hn::Max(hn::NegMulAdd(scale, hn::Load(d, r.sum + j0), one), zero);  // eq. 10 before ^k
    hn::Store(hn::IfThenElse(hn::Gt(hn::Load(d, r.cov + j0), zero), a, one), d, v);
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
