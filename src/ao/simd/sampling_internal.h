// Kernel of the scrambled Sobol points the bakers' rays are made from (core/sampling.h:
// sobol_owen_4d_batch), written once for every SIMD target (sampling.cpp): Owen scrambling in
// bit-reversed order (Laine and Karras 2011, Burley 2020's constants) and the outer reversal, 16
// points of 4 dimensions at a time. Integer arithmetic: every target gives the same bits.
#pragma once

#include <cstdint>

namespace ao::simd {

/// out[d][k] = to_unit_float(reverse_bits(laine_karras(r[d][k], key[d]))) for the 4 dimensions d
/// and the 16 points k: r holds the points' bit-reversed unscrambled coordinates, key each
/// dimension's scramble seed.
void owen_scramble_4x16(const std::uint32_t (&r)[4][16], const std::uint32_t (&key)[4], float (&out)[4][16]);

}  // namespace ao::simd
