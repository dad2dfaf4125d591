// SPDX-License-Identifier: Apache-2.0
// Kernels of the voxelizer's bit columns (bits_internal.h), compiled once per SIMD target: 64-bit
// words in the lanes, the prefix XOR by six shifts (a word's bits are independent columns' voxels
// only along its column, so the shifts stay inside a lane), popcount where the target has it as an
// instruction (AVX3_DL: VPOPCNTQ) and by Highway's bit arithmetic elsewhere.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/simd/bits_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <bit>

#include <hwy/highway.h>

#include "ao/simd/bits_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

using D64 = hn::ScalableTag<std::uint64_t>;

template <class V>
HWY_INLINE V PrefixXor(V x) {
  x = hn::Xor(x, hn::ShiftLeft<1>(x));
  x = hn::Xor(x, hn::ShiftLeft<2>(x));
  x = hn::Xor(x, hn::ShiftLeft<4>(x));
  x = hn::Xor(x, hn::ShiftLeft<8>(x));
  x = hn::Xor(x, hn::ShiftLeft<16>(x));
  return hn::Xor(x, hn::ShiftLeft<32>(x));
}

HWY_INLINE std::uint64_t PrefixXorWord(std::uint64_t x) {
  x ^= x << 1;
  x ^= x << 2;
  x ^= x << 4;
  x ^= x << 8;
  x ^= x << 16;
  return x ^ (x << 32);
}

void PrefixXorInWords(std::uint64_t* words, std::size_t n) {
  const D64 d;
  const std::size_t lanes = hn::Lanes(d);
  std::size_t w = 0;
  for (; w + lanes <= n; w += lanes) hn::StoreU(PrefixXor(hn::LoadU(d, words + w)), d, words + w);
  for (; w < n; ++w) words[w] = PrefixXorWord(words[w]);
}

std::size_t OrIntoAndCount(std::uint64_t* acc, const std::uint64_t* row, std::size_t n) {
  const D64 d;
  const std::size_t lanes = hn::Lanes(d);
  auto count = hn::Zero(d);
  std::size_t w = 0;
  for (; w + lanes <= n; w += lanes) {
    const auto x = hn::LoadU(d, row + w);
    hn::StoreU(hn::Or(hn::LoadU(d, acc + w), x), d, acc + w);
    count = hn::Add(count, hn::PopulationCount(x));
  }
  std::size_t set = hn::GetLane(hn::SumOfLanes(d, count));
  for (; w < n; ++w) {
    acc[w] |= row[w];
    set += static_cast<std::size_t>(std::popcount(row[w]));
  }
  return set;
}

std::size_t CountSetBits(const std::uint64_t* words, std::size_t n) {
  const D64 d;
  const std::size_t lanes = hn::Lanes(d);
  auto count = hn::Zero(d);
  std::size_t w = 0;
  for (; w + lanes <= n; w += lanes) count = hn::Add(count, hn::PopulationCount(hn::LoadU(d, words + w)));
  std::size_t set = hn::GetLane(hn::SumOfLanes(d, count));
  for (; w < n; ++w) set += static_cast<std::size_t>(std::popcount(words[w]));
  return set;
}

}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ao::simd {

HWY_EXPORT(PrefixXorInWords);
HWY_EXPORT(OrIntoAndCount);
HWY_EXPORT(CountSetBits);

void prefix_xor_in_words(std::uint64_t* words, std::size_t n) { HWY_DYNAMIC_DISPATCH(PrefixXorInWords)(words, n); }

std::size_t or_into_and_count(std::uint64_t* acc, const std::uint64_t* row, std::size_t n) {
  return HWY_DYNAMIC_DISPATCH(OrIntoAndCount)(acc, row, n);
}

std::size_t count_set_bits(const std::uint64_t* words, std::size_t n) { return HWY_DYNAMIC_DISPATCH(CountSetBits)(words, n); }

}  // namespace ao::simd
#endif
