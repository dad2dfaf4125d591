// SPDX-License-Identifier: Apache-2.0
// Kernel of voxel cone traced AO on the world grid (cone_internal.h; methods/cone_world.cpp for the
// tables, docs/methods/cone.md for the method and its speed), compiled once per SIMD target. Per
// pixel: the prism pattern turned and the cones' axes taken into the grid (vectors over prisms and
// cones), every sphere of every cone placed and tested against the window masks with no branch
// between spheres (vectors over slots, 64-bit mask gathers), then each cone front to back over the
// spheres that passed, a sphere's prisms counted a vector at a time (one 64-bit load per prism,
// masks and popcount). Sums over prisms run in prism order and multiply-adds are written out
// (MulAdd), compiled without contraction: targets with FMA agree bit for bit.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/methods/cone/cone_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <algorithm>
#include <iterator>
#include <bit>
#include <cmath>
#include <cstring>
#include <utility>

#include <hwy/highway.h>

#include "ao/core/error.h"
#include "ao/methods/cone/cone_internal.h"
#include "ao/simd/aligned_internal.h"
#include "ao/methods/cone/cone_kernel_internal.h"
#include "ao/simd/vec_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

namespace {

using D64 = hn::ScalableTag<std::uint64_t>;  // 64-bit words: column and window loads
using DI64 = hn::RebindToSigned<D64>;
using DH = hn::Rebind<float, D64>;           // floats alongside the words (half a vector)
using DHI = hn::Rebind<std::int32_t, D64>;
using DHU = hn::Rebind<std::uint32_t, D64>;
using V64 = hn::Vec<D64>;
using VH = hn::Vec<DH>;
using VHI = hn::Vec<DHI>;

// Bits of a mask of (at most 8) lanes, lane 0 in bit 0: AVX-512's mask register itself, else
// through StoreMaskBits.
template <class D>
HWY_INLINE unsigned mask_bits(D d, hn::Mask<D> m) {
#if HWY_TARGET <= HWY_AVX3
  (void)d;
  return static_cast<unsigned>(m.raw) & 0xFFu;
#else
  std::uint8_t b[8] = {};
  hn::StoreMaskBits(d, m, b);
  return b[0];
#endif
}

// solid + the lanes of `len` added one by one in lane order (the order of the scalar sum, so every
// target gives the same bits): in registers where the vector is one of SSE's or AVX's.
HWY_INLINE float add_in_order(float solid, VH len) {
#if HWY_TARGET <= HWY_AVX3
  const __m128 a = _mm256_castps256_ps128(len.raw), b = _mm256_extractf128_ps(len.raw, 1);
  __m128 t = _mm_set_ss(solid);
  t = _mm_add_ss(t, a), t = _mm_add_ss(t, _mm_movehdup_ps(a)), t = _mm_add_ss(t, _mm_movehl_ps(a, a)), t = _mm_add_ss(t, _mm_shuffle_ps(a, a, 3));
  t = _mm_add_ss(t, b), t = _mm_add_ss(t, _mm_movehdup_ps(b)), t = _mm_add_ss(t, _mm_movehl_ps(b, b)), t = _mm_add_ss(t, _mm_shuffle_ps(b, b, 3));
  return _mm_cvtss_f32(t);
#elif HWY_TARGET <= HWY_AVX2
  const __m128 a = len.raw;
  __m128 t = _mm_set_ss(solid);
  t = _mm_add_ss(t, a), t = _mm_add_ss(t, _mm_movehdup_ps(a)), t = _mm_add_ss(t, _mm_movehl_ps(a, a)), t = _mm_add_ss(t, _mm_shuffle_ps(a, a, 3));
  return _mm_cvtss_f32(t);
#else
  HWY_ALIGN float l[8];
  hn::Store(len, DH(), l);
  for (std::size_t k = 0; k < hn::Lanes(DH()); ++k) solid += l[k];
  return solid;
#endif
}

// A 64-bit word per lane from base + offset bytes (unaligned) where bit l of `bits` is set, 0 in
// the other lanes, whose offsets must then still be readable except on AVX-512 (masked gathers).
HWY_INLINE V64 gather_words(unsigned bits, const std::uint64_t* base, hn::Vec<DI64> offset_bytes) {
#if HWY_TARGET <= HWY_AVX3
  return V64{_mm512_mask_i64gather_epi64(_mm512_setzero_si512(), static_cast<__mmask8>(bits), offset_bytes.raw, base, 1)};
#else
  (void)bits;
  return hn::GatherOffset(D64(), base, offset_bytes);
#endif
}

// 64-bit lanes (small non-negative integers) as floats alongside.
HWY_INLINE VH to_float(V64 v) { return hn::ConvertTo(DH(), hn::BitCast(DHI(), hn::TruncateTo(DHU(), v))); }

// Everything of one call that does not change from pixel to pixel, and one pixel's scratch.
struct Kernel {
  const VoxelGrid& g;
  const ConeTables& tb;
  float weight;  // every cone stands for a cell of equal measure
  // The pixel's turned prism pattern, the cones' axes in voxels and chain scales, and per slot the
  // sphere's centre (voxels) and radius scale and the bit arrays "wider than the largest window"
  // and "passed" (sampled and the window masks say maybe; wide: the blocks decide).
  // On the stack, at the largest sizes the parameters allow (about 18 KB).
  HWY_ALIGN float u[kMaxConePrisms], v[kMaxConePrisms], ax[kMaxCones], ay[kMaxCones], az[kMaxCones], scale[kMaxCones];
  HWY_ALIGN float cx[kMaxConeSlots], cy[kMaxConeSlots], cz[kMaxConeSlots], rs[kMaxConeSlots];
  std::uint8_t wide[kMaxConeSlots / 8 + 8], pass[kMaxConeSlots / 8 + 8];

  Kernel(const VoxelGrid& grid, const ConeTables& tables) : g(grid), tb(tables), weight(1.0f / static_cast<float>(tables.cones)) {
    AO_ASSERT(tables.prism_lanes <= kMaxConePrisms && tables.cones_padded <= kMaxCones && tables.slots <= kMaxConeSlots);
    // The bytes past the slots stay 0 (bits() reads up to 4 bytes from any slot's byte).
    std::fill(std::begin(wide), std::end(wide), 0), std::fill(std::begin(pass), std::end(pass), 0);
  }

  static bool bit(const std::uint8_t* b, int i) { return (b[static_cast<std::size_t>(i) >> 3] >> (i & 7)) & 1u; }
  // `count` (<= 25) bits of a bit array from bit `first`.
  static std::uint32_t bits(const std::uint8_t* b, int first, int count) {
    std::uint32_t word;
    std::memcpy(&word, b + (first >> 3), sizeof word);
    return (word >> (first & 7)) & ((1u << count) - 1);
  }

  // The disk points turned by the pixel's (rot_c, rot_s).
  void turn(float rot_c, float rot_s) {
    const DF d;
    const VF c = hn::Set(d, rot_c), s = hn::Set(d, rot_s);
    for (int k = 0; k < tb.prism_lanes; k += static_cast<int>(hn::Lanes(d))) {
      const VF du = hn::Load(d, tb.disk_u + k), dv = hn::Load(d, tb.disk_v + k);
      hn::Store(hn::MulSub(du, c, hn::Mul(dv, s)), d, u + k);
      hn::Store(hn::MulAdd(du, s, hn::Mul(dv, c)), d, v + k);
    }
  }

  // The pattern's cone axes turned into the pixel's frame (world space) and into voxels.
  void axes(const Frame& f, int pattern) {
    const DF d;
    const std::size_t o = static_cast<std::size_t>(pattern) * tb.cones_padded;
    const VF tx = hn::Set(d, f.t.x), ty = hn::Set(d, f.t.y), tz = hn::Set(d, f.t.z), bx = hn::Set(d, f.b.x), by = hn::Set(d, f.b.y),
             bz = hn::Set(d, f.b.z), nx = hn::Set(d, f.n.x), ny = hn::Set(d, f.n.y), nz = hn::Set(d, f.n.z);
    const VF ix = hn::Set(d, tb.inv_voxel.x), iy = hn::Set(d, tb.inv_voxel.y), iz = hn::Set(d, tb.inv_voxel.z);
    for (int c = 0; c < tb.cones; c += static_cast<int>(hn::Lanes(d))) {
      const VF lx = hn::Load(d, tb.axis_x + o + c), ly = hn::Load(d, tb.axis_y + o + c), lz = hn::Load(d, tb.axis_z + o + c);
      const VF wx = hn::MulAdd(nx, lz, hn::MulAdd(bx, ly, hn::Mul(tx, lx)));
      const VF wy = hn::MulAdd(ny, lz, hn::MulAdd(by, ly, hn::Mul(ty, lx)));
      const VF wz = hn::MulAdd(nz, lz, hn::MulAdd(bz, ly, hn::Mul(tz, lx)));
      hn::Store(hn::Load(d, tb.axis_scale + o + c), d, scale + c);
      // World (x, y, z) is the grid's (i, k, j).
      hn::Store(hn::Mul(wx, ix), d, ax + c), hn::Store(hn::Mul(wz, iy), d, ay + c), hn::Store(hn::Mul(wy, iz), d, az + c);
    }
  }

  // Every slot's sphere placed from the pixel's grid point and tested against the window masks
  // (deviation 6 of docs/methods/cone.md; exact: a skipped sphere's prisms read no solid voxel).
  void place(float gx, float gy, float gz) {
    const DH dh;
    const DHI dhi;
    const DI64 di64;
    const int lanes = static_cast<int>(hn::Lanes(dh));
    constexpr float kInvC = 1.0f / VoxelGrid::kCellXY;
    const VH zero = hn::Zero(dh), one = hn::Set(dh, 1.0f), quarter = hn::Set(dh, kInvC);
    const VH fdnx = hn::Set(dh, static_cast<float>(g.dnx - 1)), fdny = hn::Set(dh, static_cast<float>(g.dny - 1)),
             fbits = hn::Set(dh, static_cast<float>(g.depth_bits - 1));
    // Margins for rounding: 1e-3 voxels, in cells along x and y.
    const VH margin_c = hn::Set(dh, 1e-3f * kInvC), margin_z = hn::Set(dh, 1e-3f);
    const VH vgx = hn::Set(dh, gx), vgy = hn::Set(dh, gy), vgz = hn::Set(dh, gz);
    const VHI dnx = hn::Set(dhi, g.dnx), cap = hn::Set(dhi, VoxelGrid::kWindowCap), c63 = hn::Set(dhi, 63);
    const V64 ones = hn::Set(D64(), ~std::uint64_t{0});
    const bool permute = tb.cones <= lanes;  // the cones' values fit one vector: a permute per slot, else a gather
    const VH ps = hn::LoadU(dh, scale), pax = hn::LoadU(dh, ax), pay = hn::LoadU(dh, ay), paz = hn::LoadU(dh, az);
    for (int i = 0; i < tb.slots; i += lanes) {
      const VHI c = hn::LoadU(dhi, tb.slot_cone + i);
      VH s, cax, cay, caz;
      if (permute) {
        const auto idx = hn::IndicesFromVec(dh, c);
        s = hn::TableLookupLanes(ps, idx), cax = hn::TableLookupLanes(pax, idx), cay = hn::TableLookupLanes(pay, idx), caz = hn::TableLookupLanes(paz, idx);
      } else {
        s = hn::GatherIndex(dh, scale, c), cax = hn::GatherIndex(dh, ax, c), cay = hn::GatherIndex(dh, ay, c),
        caz = hn::GatherIndex(dh, az, c);
      }
      // The chain, affine in the cone's scale s (cone_internal.h).
      const VH d = hn::MulAdd(hn::LoadU(dh, tb.dist_a + i), s, hn::LoadU(dh, tb.dist_b + i));
      const VH px = hn::MulAdd(cax, d, vgx), py = hn::MulAdd(cay, d, vgy), pz = hn::MulAdd(caz, d, vgz);
      const VH r = hn::Min(hn::MulAdd(hn::LoadU(dh, tb.rad_a + i), s, hn::LoadU(dh, tb.rad_b + i)), one);
      const unsigned use = mask_bits(dh, hn::Ge(hn::MulAdd(hn::LoadU(dh, tb.use_a + i), s, hn::LoadU(dh, tb.use_b + i)), zero));
      hn::Store(px, dh, cx + i), hn::Store(py, dh, cy + i), hn::Store(pz, dh, cz + i), hn::Store(r, dh, rs + i);
      // The sphere's prisms read columns within (ex, ey) of its centre and voxels within ez along
      // them; that box of columns lies in the window anchored at its lowest cell, w = its larger
      // span in cells (clamped into the grid, which only drops columns no prism can read), whose
      // mask is checked over the box's z cells cl..ch. A box wider than the largest window goes to
      // the blocks. Indices are int(min(max(x, 0), n - 1)): clamp(floor(x), 0, n - 1) for x >= 0, 0 for NaN.
      const VH ex = hn::MulAdd(hn::LoadU(dh, tb.box_x + i), r, margin_c), ey = hn::MulAdd(hn::LoadU(dh, tb.box_y + i), r, margin_c);
      const VH ez = hn::MulAdd(hn::LoadU(dh, tb.box_z + i), r, margin_z);
      const VH pxc = hn::Mul(px, quarter), pyc = hn::Mul(py, quarter);
      const auto cell = [&](VH a, VH hi) { return truncate_in_range(hn::Min(hn::Max(a, zero), hi)); };
      const VHI x0 = cell(hn::Sub(pxc, ex), fdnx), x1 = cell(hn::Add(pxc, ex), fdnx);
      const VHI y0 = cell(hn::Sub(pyc, ey), fdny), y1 = cell(hn::Add(pyc, ey), fdny);
      const VHI cl = hn::ShiftRightSame(cell(hn::Sub(pz, ez), fbits), g.cell_shift), ch = hn::ShiftRightSame(cell(hn::Add(pz, ez), fbits), g.cell_shift);
      const VHI w = hn::Max(hn::Sub(x1, x0), hn::Sub(y1, y0));
      const unsigned wid = mask_bits(dhi, hn::Gt(w, cap));
      const VHI idx = hn::Add(hn::ShiftLeft<3>(hn::Add(hn::Mul(y0, dnx), x0)), hn::Min(w, cap));  // kWindowCap + 1 = 8 masks per cell
      const V64 wm = gather_words(use, g.window.data(), hn::ShiftLeft<3>(hn::PromoteTo(di64, idx)));
      const V64 sh = hn::BitCast(D64(), hn::PromoteTo(di64, hn::Sub(c63, hn::Sub(ch, cl))));
      const V64 lo = hn::BitCast(D64(), hn::PromoteTo(di64, cl));
      const unsigned any = mask_bits(D64(), hn::Not(hn::Eq(hn::And((wm >> lo), (ones >> sh)), hn::Zero(D64()))));
      // `lanes` divides 8: a step's bits never straddle a byte, and the first step of a byte sets it.
      const auto at = static_cast<std::size_t>(i >> 3);
      const int shift = i & 7;
      const auto put = [&](std::uint8_t* b, unsigned m) { b[at] = static_cast<std::uint8_t>((shift ? b[at] : 0u) | (m << shift)); };
      put(wide, wid), put(pass, use & (any | wid));
    }
  }

  HWY_NOINLINE float scalar_prism(float gx, float gy, float gz, float rx, float ry, float h, float pu, float pv) const {
    const float fx = gx + pu * rx, fy = gy + pv * ry;
    if (!(fx >= 0.0f && fy >= 0.0f && fx < static_cast<float>(g.nx) && fy < static_cast<float>(g.ny))) return 0.0f;
    return cone_internal::solid_length(g.column(static_cast<int>(fx), static_cast<int>(fy)), g.words, g.depth_bits, gz - h, gz + h);
  }

  // The solid length of the sphere's prisms (centred at grid point (gx, gy, gz), radii rx, ry in
  // voxels, half chords h times `hs`), a vector of prisms at a time: column indices, z ranges, one
  // 64-bit load per prism starting at the byte that holds its first voxel (bits k0 .. k1 of the
  // column are then bits sh .. sh + k1 - k0 of the load, sh = k0 mod 8, or further in at the
  // column's last 8 bytes), masks and popcount. Prisms longer than the load (k1 - k0 + sh > 63) go
  // the scalar way. The ends count by the part of their voxel inside the range (solid_length).
  // Summed in prism order.
  HWY_INLINE float prisms(float gx, float gy, float gz, float rx, float ry, const float* h, float hs) const {
    const DH dh;
    const DHI dhi;
    const DI64 di64;
    const D64 d64;
    const int lanes = static_cast<int>(hn::Lanes(dh));
    const VH zero = hn::Zero(dh), one = hn::Set(dh, 1.0f), fnx = hn::Set(dh, static_cast<float>(g.nx)), fny = hn::Set(dh, static_cast<float>(g.ny)),
             fbits = hn::Set(dh, static_cast<float>(g.depth_bits));
    const VHI last_bit = hn::Set(dhi, g.depth_bits - 1), nx = hn::Set(dhi, g.nx), words = hn::Set(dhi, g.words),
              last_byte = hn::Set(dhi, 8 * g.words - 8), c63 = hn::Set(dhi, 63);
    const V64 one64 = hn::Set(d64, 1), two64 = hn::Set(d64, 2);
    const VH vs = hn::Set(dh, hs), vrx = hn::Set(dh, rx), vry = hn::Set(dh, ry), vgx = hn::Set(dh, gx), vgy = hn::Set(dh, gy), vgz = hn::Set(dh, gz);
    float solid = 0;
    for (int s0 = 0; s0 < tb.prisms; s0 += lanes) {
      const VH pu = hn::Load(dh, u + s0), pv = hn::Load(dh, v + s0), hh = hn::Mul(hn::Load(dh, h + s0), vs);
      const VH fx = hn::MulAdd(pu, vrx, vgx), fy = hn::MulAdd(pv, vry, vgy);
      const VH zlo = hn::Max(hn::Sub(vgz, hh), zero), zhi = hn::Min(hn::Add(vgz, hh), fbits);
      // Lanes past the prisms have a half chord of 0, so zhi > zlo fails for them.
      const auto inside = hn::And(hn::And(hn::Ge(fx, zero), hn::Ge(fy, zero)), hn::And(hn::Lt(fx, fnx), hn::Lt(fy, fny)));
      const auto in_range = hn::And(inside, hn::Gt(zhi, zlo));
      // Lanes out of range read column 0 (their length is 0).
      const auto ok_i = hn::RebindMask(dhi, in_range);
      const VHI ix = hn::IfThenElseZero(ok_i, truncate_in_range(hn::IfThenElseZero(in_range, fx)));
      const VHI iy = hn::IfThenElseZero(ok_i, truncate_in_range(hn::IfThenElseZero(in_range, fy)));
      const VHI k0 = hn::IfThenElseZero(ok_i, truncate_in_range(hn::IfThenElseZero(in_range, zlo)));
      const VHI k1 = hn::IfThenElseZero(ok_i, hn::Min(truncate_in_range(hn::IfThenElseZero(in_range, zhi)), last_bit));
      const VHI byte = hn::Min(hn::ShiftRight<3>(k0), last_byte);
      const VHI sh = hn::Sub(k0, hn::ShiftLeft<3>(byte)), n = hn::Sub(k1, k0);
      const auto wide_i = hn::And(ok_i, hn::Gt(hn::Add(sh, n), c63));
      const unsigned wide_bits = mask_bits(dhi, wide_i);
      const auto ok = hn::RebindMask(dh, hn::AndNot(wide_i, ok_i));
      // Byte offsets in 64 bits: a grid of 4096 x 4096 columns of 1024 bits has 2^31 bytes.
      const VHI col = hn::Mul(hn::Add(hn::Mul(iy, nx), ix), words);
      const hn::Vec<DI64> at = hn::Add(hn::ShiftLeft<3>(hn::PromoteTo(di64, col)), hn::PromoteTo(di64, byte));
      const V64 word = gather_words(mask_bits(dh, ok), g.bits.data(), at);
      const V64 x = (word >> hn::BitCast(d64, hn::PromoteTo(di64, sh)));  // bit 0 = voxel k0, bit n = voxel k1
      const V64 n64 = hn::BitCast(d64, hn::PromoteTo(di64, n));
      const VH b0 = to_float(hn::And(x, one64)), b1 = to_float(hn::And((x >> n64), one64));
      // Voxels strictly between the end voxels: bits 1 .. n - 1 of x (n >= 1; n = 0 takes `single`).
      const VH mid = to_float(hn::PopulationCount(hn::And(x, hn::Sub((one64 << n64), two64))));
      const VH fk0 = hn::ConvertTo(dh, k0), fk1 = hn::ConvertTo(dh, k1);
      // k0 == k1: bit(k0) (zhi - zlo); else bit(k0) (k0 + 1 - zlo) + between + bit(k1) (zhi - k1).
      const VH multi = hn::Add(hn::Add(hn::Mul(b0, hn::Sub(hn::Add(fk0, one), zlo)), mid), hn::Mul(b1, hn::Sub(zhi, fk1)));
      const VH single = hn::Mul(b0, hn::Sub(zhi, zlo));
      const auto one_voxel = hn::RebindMask(dh, hn::Not(hn::Lt(k0, k1)));
      VH len = hn::IfThenElseZero(ok, hn::IfThenElse(one_voxel, single, multi));
      if (wide_bits) {
        HWY_ALIGN float l[8];
        hn::Store(len, dh, l);
        for (unsigned m = wide_bits; m; m &= m - 1) {
          const int s = s0 + std::countr_zero(m);
          l[s - s0] = scalar_prism(gx, gy, gz, rx, ry, h[s] * hs, u[s], v[s]);
        }
        len = hn::Load(dh, l);
      }
      // Lanes past the prisms hold +0, and adding +0 to a sum >= +0 leaves it as it is.
      solid = add_in_order(solid, len);
    }
    return solid;
  }

  // For spheres wider than the largest window: the OR of every block the sphere's box touches.
  HWY_NOINLINE bool maybe_solid_blocks(float gx, float gy, float gz, float rx, float ry, float rz) const {
    constexpr float kInvB = 1.0f / VoxelGrid::kBlock;
    const int bx0 = std::max(0, static_cast<int>(std::floor((gx - rx) * kInvB)));
    const int bx1 = std::min(g.bnx - 1, static_cast<int>(std::floor((gx + rx) * kInvB)));
    const int by0 = std::max(0, static_cast<int>(std::floor((gy - ry) * kInvB)));
    const int by1 = std::min(g.bny - 1, static_cast<int>(std::floor((gy + ry) * kInvB)));
    const int k0 = static_cast<int>(std::floor(std::max(gz - rz, -1.0f))), k1 = static_cast<int>(std::min(gz + rz, 1e6f)) + 1;
    for (int by = by0; by <= by1; ++by)
      for (int bx = bx0; bx <= bx1; ++bx)
        if (any_bits(g.block(bx, by), g.words, k0, k1)) return true;
    return false;
  }

  // Obstructed fraction of slot i's sphere (sec. III-C1): prisms through its great disk's samples,
  // each spanning the sphere's chord; Monte Carlo over the disk: its volume ~ the sum of the chords,
  // its obstructed volume ~ the sum of their solid lengths.
  HWY_INLINE float fraction(int i) const {
    const auto si = static_cast<std::size_t>(i);
    const int k = tb.slot_sphere[i];
    const float px = cx[si], py = cy[si], pz = cz[si], r = rs[si];
    const float rx = tb.sphere_rx[k] * r, ry = tb.sphere_ry[k] * r;
    if (bit(wide, i) && !maybe_solid_blocks(px, py, pz, rx, ry, tb.sphere_rz[k] * r)) return 0.0f;
    const float solid = prisms(px, py, pz, rx, ry, tb.half_chord + static_cast<std::size_t>(k) * tb.prism_lanes, r);
    const float chord = tb.sphere_chord[k] * r;
    return chord > 0 ? std::min(1.0f, solid / chord) : 0.0f;
  }

  // Front to back along each cone (sec. III-C2, Fig. 8): each sphere absorbs its obstructed
  // fraction f of the rays that reach it, T *= 1 - f, until T <= kOpaque; V = the cones' mean T.
  float visibility() const {
    float vis = 0;
    for (int c = 0; c < tb.cones; ++c) {
      float tr = 1.0f;
      const int i0 = c * tb.per_cone;
      // A sphere that failed the coarse test has f = 0 and leaves T as it is: only the passed
      // ones, in order (bit j: sphere j of the cone).
      for (std::uint32_t m = bits(pass, i0, tb.per_cone); m && tr > cone_internal::kOpaque; m &= m - 1)
        tr *= 1.0f - fraction(i0 + std::countr_zero(m));
      vis += weight * tr;
    }
    return std::clamp(vis, 0.0f, 1.0f);
  }
};

}  // namespace

void TraceCones(const GBuffer& gb, const VoxelGrid& grid, const ConeTables& tables, const ConeView& view, int x0, int x1, int y0, int y1,
                ImageView<float> out) {
  Kernel k(grid, tables);
  const Vec3 inv = tables.inv_voxel;
  const int period = view.pattern_period;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      if (!gb.covered(x, y)) {
        out(x, y) = 1.0f;
        continue;
      }
      const Vec3 pos = view.basis.to_world(gb.position(x, y)) + view.eye, n = normalize(view.basis.to_world(gb.normal(x, y)));
      const Frame frame = Frame::from_normal(n);
      const int pattern = (y & (period - 1)) * period + (x & (period - 1));
      k.turn(tables.turn[2 * pattern], tables.turn[2 * pattern + 1]);
      k.axes(frame, pattern);
      // World (x, y, z) is the grid's (i, k, j).
      k.place((pos.x - view.grid_origin.x) * inv.x, (pos.z - view.grid_origin.z) * inv.y, (pos.y - view.grid_origin.y) * inv.z);
      out(x, y) = k.visibility();
    }
}

}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ao::simd {

HWY_EXPORT(TraceCones);

void trace_cones(const GBuffer& gb, const VoxelGrid& grid, const ConeTables& tables, const ConeView& view, int x0, int x1, int y0, int y1,
                 ImageView<float> out) {
  HWY_DYNAMIC_DISPATCH(TraceCones)(gb, grid, tables, view, x0, x1, y0, y1, out);
}

}  // namespace ao::simd
#endif
