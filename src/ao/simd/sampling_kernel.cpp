// SPDX-License-Identifier: Apache-2.0
// Kernels of the sample points (sampling_internal.h), compiled once per SIMD target: the hash and
// the bit reversal of core/sampling.cpp, lane-wise over the 16 points of a batch; and the
// reference's cosine-weighted directions, lane-wise over a packet's samples.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/simd/sampling_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <algorithm>
#include <array>
#include <cmath>

#include <hwy/highway.h>

#include "ao/core/sampling.h"
#include "ao/simd/sampling_internal.h"
#include "ao/simd/vec_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

namespace {

// Swaps the bit fields selected by `mask` with those `shift` bits above them.
template <int kShift>
HWY_INLINE VU swap_bits(VU x, std::uint32_t mask) {
  const VU m = hn::Set(DU(), mask);
  return hn::Or(hn::And(hn::ShiftRight<kShift>(x), m), hn::ShiftLeft<kShift>(hn::And(x, m)));
}

HWY_INLINE VU reverse_bits(VU x) {
  x = swap_bits<1>(x, 0x55555555u);
  x = swap_bits<2>(x, 0x33333333u);
  x = swap_bits<4>(x, 0x0f0f0f0fu);
  x = swap_bits<8>(x, 0x00ff00ffu);
  return hn::Or(hn::ShiftRight<16>(x), hn::ShiftLeft<16>(x));
}

// Laine and Karras's hash with Burley's constants: each bit depends only on lower bits.
HWY_INLINE VU laine_karras(VU x, std::uint32_t seed) {
  const DU du;
  x = hn::Add(x, hn::Set(du, seed));
  x = hn::Xor(x, hn::Mul(x, hn::Set(du, 0x6c50b47cu)));
  x = hn::Xor(x, hn::Mul(x, hn::Set(du, 0xb82f1e52u)));
  x = hn::Xor(x, hn::Mul(x, hn::Set(du, 0xc7afe638u)));
  return hn::Xor(x, hn::Mul(x, hn::Set(du, 0x8d22f6e6u)));
}

// One sample of cosine_directions, for the lanes past the last whole vector: the vector code's
// operations in its order, so that a lane's bits do not depend on where the vector ends.
HWY_INLINE bool cosine_direction(const CosineSamples& s, int k, float& dx, float& dy, float& dz) {
  float u = s.u0[k] + s.shift;
  u = u >= 1.0f ? u - 1.0f : u;
  const float r = std::sqrt(u), z = std::sqrt(std::max(0.0f, 1.0f - u));
  const float x = r * s.cos_phi[k], y = r * s.sin_phi[k];
  dx = s.t[0] * x + s.b[0] * y + s.n[0] * z;
  dy = s.t[1] * x + s.b[1] * y + s.n[1] * z;
  dz = s.t[2] * x + s.b[2] * y + s.n[2] * z;
  return dx * s.ng[0] + dy * s.ng[1] + dz * s.ng[2] > 0.0f;
}

}  // namespace

int CosineDirections(const CosineSamples& s, int count, int live, float* HWY_RESTRICT dir_x, float* HWY_RESTRICT dir_y, float* HWY_RESTRICT dir_z,
                     int* HWY_RESTRICT valid) {
  const DF d;
  const DI di;
  const int lanes = static_cast<int>(hn::Lanes(d));
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f), shift = hn::Set(d, s.shift);
  const VF tx = hn::Set(d, s.t[0]), ty = hn::Set(d, s.t[1]), tz = hn::Set(d, s.t[2]);
  const VF bx = hn::Set(d, s.b[0]), by = hn::Set(d, s.b[1]), bz = hn::Set(d, s.b[2]);
  const VF nx = hn::Set(d, s.n[0]), ny = hn::Set(d, s.n[1]), nz = hn::Set(d, s.n[2]);
  const VF gx = hn::Set(d, s.ng[0]), gy = hn::Set(d, s.ng[1]), gz = hn::Set(d, s.ng[2]);
  int on_count = 0, k = 0;
  for (; k + lanes <= count; k += lanes) {
    VF u = hn::Add(hn::LoadU(d, s.u0 + k), shift);
    u = hn::IfThenElse(hn::Ge(u, one), hn::Sub(u, one), u);
    const VF r = hn::Sqrt(u), z = hn::Sqrt(hn::Max(zero, hn::Sub(one, u)));  // Malley: the disk lifted to the hemisphere
    const VF x = hn::Mul(r, hn::LoadU(d, s.cos_phi + k)), y = hn::Mul(r, hn::LoadU(d, s.sin_phi + k));
    const VF dx = hn::Add(hn::Add(hn::Mul(tx, x), hn::Mul(bx, y)), hn::Mul(nx, z));
    const VF dy = hn::Add(hn::Add(hn::Mul(ty, x), hn::Mul(by, y)), hn::Mul(ny, z));
    const VF dz = hn::Add(hn::Add(hn::Mul(tz, x), hn::Mul(bz, y)), hn::Mul(nz, z));
    hn::StoreU(dx, d, dir_x + k), hn::StoreU(dy, d, dir_y + k), hn::StoreU(dz, d, dir_z + k);
    const MF above = hn::Gt(hn::Add(hn::Add(hn::Mul(dx, gx), hn::Mul(dy, gy)), hn::Mul(dz, gz)), zero);
    const MF on = hn::And(above, hn::RebindMask(d, hn::Lt(hn::Iota(di, k), hn::Set(di, live))));
    hn::StoreU(hn::VecFromMask(di, hn::RebindMask(di, on)), di, valid + k);
    on_count += static_cast<int>(hn::CountTrue(d, on));
  }
  for (; k < count; ++k) {
    const bool on = cosine_direction(s, k, dir_x[k], dir_y[k], dir_z[k]) && k < live;
    valid[k] = on ? -1 : 0;
    on_count += on;
  }
  return on_count;
}

void OwenScramble4x16(const std::uint32_t (&r)[4][16], const std::uint32_t (&key)[4], float (&out)[4][16]) {
  const DF d;
  const DU du;
  const int lanes = static_cast<int>(hn::Lanes(d));
  const VF scale = hn::Set(d, 0x1.0p-24f);  // to_unit_float: the top 24 bits over 2^24
  for (int dim = 0; dim < 4; ++dim)
    for (int k = 0; k < 16; k += lanes) {
      const VU bits = reverse_bits(laine_karras(hn::LoadU(du, &r[dim][k]), key[dim]));
      hn::StoreU(hn::Mul(hn::ConvertTo(d, hn::BitCast(DI(), hn::ShiftRight<8>(bits))), scale), d, &out[dim][k]);
    }
}

}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ao::simd {

HWY_EXPORT(OwenScramble4x16);
HWY_EXPORT(CosineDirections);

void owen_scramble_4x16(const std::uint32_t (&r)[4][16], const std::uint32_t (&key)[4], float (&out)[4][16]) {
  HWY_DYNAMIC_DISPATCH(OwenScramble4x16)(r, key, out);
}

int cosine_directions(const CosineSamples& s, int count, int live, float* dir_x, float* dir_y, float* dir_z, int* valid) {
  return HWY_DYNAMIC_DISPATCH(CosineDirections)(s, count, live, dir_x, dir_y, dir_z, valid);
}

}  // namespace ao::simd

namespace ao {

void sobol_owen_4d_batch(std::uint32_t first, int count, std::uint32_t seed, float (&out)[4][16]) {
  const std::array<std::uint32_t, 4> keys = sobol_owen_4d_keys(seed);
  const std::uint32_t key[4] = {keys[0], keys[1], keys[2], keys[3]};
  alignas(64) std::uint32_t r[4][16] = {};
  sobol_reversed_4d_batch(first, count, r);
  // Hash and outer reversal: shifts, masks and multiplies, 16 lanes at once.
  simd::owen_scramble_4x16(r, key, out);
}

}  // namespace ao
#endif
