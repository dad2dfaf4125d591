// Kernel of the scrambled Sobol points (sampling_internal.h), compiled once per SIMD target: the
// hash and the bit reversal of core/sampling.cpp, lane-wise over the 16 points of a batch.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/simd/sampling.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

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

}  // namespace

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

void owen_scramble_4x16(const std::uint32_t (&r)[4][16], const std::uint32_t (&key)[4], float (&out)[4][16]) {
  HWY_DYNAMIC_DISPATCH(OwenScramble4x16)(r, key, out);
}

}  // namespace ao::simd
#endif
