// SPDX-License-Identifier: Apache-2.0
// The per-pixel hash every method's sampling is keyed by (core/sampling.h), read by C++ and by the
// GPU shaders (gpu/shaders/common.glsl) alike, so both backends draw the same samples bit for bit:
// the "lowbias32" finaliser, hash_combine, pixel_seed and to_unit_float. Written in the language
// both compilers read (core/shared.h).
#ifndef AO_CORE_HASH_SHARED_H_
#define AO_CORE_HASH_SHARED_H_
#include "ao/core/shared.h"
AO_SHARED_BEGIN

/// The "lowbias32" finaliser's multipliers, and the golden-ratio increment of Boost's hash_combine
/// (also the SIMD kernels' vector forms of hash32 and hash_combine use them).
AO_CONST uint kHashMultiplier1 = 0x7feb352du;
AO_CONST uint kHashMultiplier2 = 0x846ca68bu;
AO_CONST uint kHashGolden = 0x9e3779b9u;

/// 32-bit integer finaliser with good avalanche (the "lowbias32" constants).
AO_FN uint hash32(uint x) {
  x ^= x >> 16u;
  x *= kHashMultiplier1;
  x ^= x >> 15u;
  x *= kHashMultiplier2;
  x ^= x >> 16u;
  return x;
}
/// Mixes `v` into `seed`, then finalises.
AO_FN uint hash_combine(uint seed, uint v) { return hash32(seed ^ (v + kHashGolden + (seed << 6u) + (seed >> 2u))); }
/// Seed for one pixel of one image: mixes the user's seed with the pixel coordinates.
AO_FN uint pixel_seed(uint seed, int x, int y) { return hash_combine(hash_combine(hash32(seed), uint(x)), uint(y)); }
/// Maps 32 random bits to a float in [0, 1): the top 24 bits over 2^24, exact in a float.
AO_FN float to_unit_float(uint bits) { return float(bits >> 8u) * (1.0f / 16777216.0f); }

AO_SHARED_END
#endif  // AO_CORE_HASH_SHARED_H_
