// SPDX-License-Identifier: Apache-2.0
// The kernel layer's vector vocabulary, included by each kernel source once per target (Highway's
// "-inl.h" convention: the guard flips with HWY_TARGET_TOGGLE so every target gets its own copy).
// Kernels speak in these terms: a vector of floats across pixels (or prisms, or taps), its lane
// mask, and a few operations Highway 1.0 spells at greater cost or not at all on x86.
#if defined(AO_SIMD_VEC_INTERNAL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef AO_SIMD_VEC_INTERNAL_H_
#undef AO_SIMD_VEC_INTERNAL_H_
#else
#define AO_SIMD_VEC_INTERNAL_H_
#endif

#include <cstdint>

#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

using DF = hn::ScalableTag<float>;      // floats, as many as the target's vectors hold
using DI = hn::RebindToSigned<DF>;      // int32 lanes alongside
using DU = hn::RebindToUnsigned<DF>;    // uint32 lanes alongside
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;
using VU = hn::Vec<DU>;
using MF = hn::Mask<DF>;

/// float -> int32 by truncation for values known to lie in int32's range (clamped pixel and voxel
/// coordinates), for full or partial vectors of floats: the instruction alone, without Highway's
/// fix-up of out-of-range lanes.
template <class V>
HWY_INLINE auto truncate_in_range(V v) {
  using DS = hn::RebindToSigned<hn::DFromV<V>>;
#if HWY_TARGET <= HWY_SSSE3
  using R = hn::Vec<DS>;
#endif
#if HWY_TARGET <= HWY_AVX3
  if constexpr (sizeof(v.raw) == 64) return R{_mm512_cvttps_epi32(v.raw)};
#endif
#if HWY_TARGET <= HWY_AVX2
  if constexpr (sizeof(v.raw) == 32) return R{_mm256_cvttps_epi32(v.raw)};
#endif
#if HWY_TARGET <= HWY_SSSE3
  if constexpr (sizeof(v.raw) == 16) return R{_mm_cvttps_epi32(v.raw)};
#endif
  return hn::ConvertTo(DS(), v);
}

/// table[index] for a table of 32 floats (index in [0, 32)): two in-register permutes where the
/// target has them (AVX-512), else a gather from the table (in L1).
HWY_INLINE VF lookup32(const float* table, VI index) {
#if HWY_TARGET <= HWY_AVX3
  return VF{_mm512_permutex2var_ps(_mm512_loadu_ps(table), index.raw, _mm512_loadu_ps(table + 16))};
#else
  return hn::GatherIndex(DF(), table, index);
#endif
}

/// table[index] for a table of 16 floats (index in [0, 16)): one in-register permute where the
/// target has it (AVX-512), else a gather from the table (in L1).
HWY_INLINE VF lookup16(const float* table, VI index) {
#if HWY_TARGET <= HWY_AVX3
  return VF{_mm512_permutexvar_ps(index.raw, _mm512_loadu_ps(table))};
#else
  return hn::GatherIndex(DF(), table, index);
#endif
}

/// base[index] where `mask` is set, 0 elsewhere. Masked-off lanes read nothing where the target
/// has masked gathers (AVX2, AVX-512: lines a free ray would not have touched stay out of the cache);
/// elsewhere (SSE4, EMU128) every lane reads, so `index` must be a valid index in all lanes.
HWY_INLINE VF gather_where(MF mask, const float* base, VI index) {
#if HWY_TARGET <= HWY_AVX3
  return VF{_mm512_mask_i32gather_ps(_mm512_setzero_ps(), mask.raw, index.raw, base, 4)};
#elif HWY_TARGET <= HWY_AVX2
  return VF{_mm256_mask_i32gather_ps(_mm256_setzero_ps(), base, index.raw, mask.raw, 4)};
#else
  return hn::IfThenElseZero(mask, hn::GatherIndex(DF(), base, index));
#endif
}

/// The same for 32-bit words.
HWY_INLINE VU gather_where(hn::Mask<DU> mask, const std::uint32_t* base, VI index) {
#if HWY_TARGET <= HWY_AVX3
  return VU{_mm512_mask_i32gather_epi32(_mm512_setzero_si512(), mask.raw, index.raw, base, 4)};
#elif HWY_TARGET <= HWY_AVX2
  return VU{_mm256_mask_i32gather_epi32(_mm256_setzero_si256(), reinterpret_cast<const int*>(base), index.raw, mask.raw, 4)};
#else
  return hn::IfThenElseZero(mask, hn::GatherIndex(DU(), base, index));
#endif
}

/// Lanes of `v` selected by `mask` incremented by `add`, the others kept.
HWY_INLINE VF add_where(MF mask, VF v, VF add) { return hn::IfThenElse(mask, hn::Add(v, add), v); }

}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // AO_SIMD_VEC_INTERNAL_H_
