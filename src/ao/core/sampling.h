// SPDX-License-Identifier: Apache-2.0
// Hashing and sample generation. Per-pixel randomness comes from hash(seed, pixel, sample), never
// from thread-local state, so results do not depend on the thread count.
#pragma once

#include <array>
#include <cstdint>

#include "ao/core/hash_shared.h"  // hash32, hash_combine, pixel_seed, to_unit_float (shared with the GPU shaders)
#include "ao/core/math.h"

namespace ao {

using shared::hash32;
using shared::hash_combine;
using shared::pixel_seed;
using shared::to_unit_float;

/// Point `index` of the 2-D Sobol sequence with hash-based nested uniform (Owen) scrambling and
/// index shuffling keyed by `seed` (Burley 2020, "Practical hash-based Owen scrambling").
/// Every prefix of 2^k points is stratified in all elementary intervals; different seeds give
/// statistically independent sets, so the per-pixel mean has an honest sample variance.
Vec2 sobol_owen_2d(std::uint32_t index, std::uint32_t seed);

/// Point `index` of the first four dimensions of the Sobol sequence (0 and 1 as in sobol_owen_2d,
/// 2 and 3 from the polynomials x^2 + x + 1 and x^3 + x + 1 with Joe and Kuo's direction numbers),
/// each dimension Owen-scrambled with its own key from `seed` (Burley 2020's hash, no index
/// shuffle). Every prefix of 2^k points is stratified in all elementary intervals of dimensions
/// 0 and 1 and is a net of the four dimensions jointly; different seeds give independent sets.
std::array<float, 4> sobol_owen_4d(std::uint32_t index, std::uint32_t seed);

/// The per-dimension scrambling keys sobol_owen_4d derives from `seed`.
std::array<std::uint32_t, 4> sobol_owen_4d_keys(std::uint32_t seed);

/// Points first .. first + count - 1 (count in [0, 16]) of sobol_owen_4d's sequence before
/// scrambling, into r[d][k]: dimension 0 the index, dimensions 1-3 bit-reversed (the inner
/// reversal of nested uniform scrambling); entries k >= count are left as they are. The SIMD
/// kernels scramble a batch of them (simd/sampling_internal.h: sobol_owen_4d_batch).
void sobol_reversed_4d_batch(std::uint32_t first, int count, std::uint32_t (&r)[4][16]);

/// Cosine-weighted direction on the hemisphere about +z from u in [0,1)^2: Shirley-Chiu concentric
/// disk mapping, lifted to the hemisphere (Malley's method). pdf = cos(theta) / pi.
Vec3 cosine_hemisphere(Vec2 u);

/// Uniform direction on the unit sphere from u in [0,1)^2.
Vec3 uniform_sphere(Vec2 u);

}  // namespace ao
