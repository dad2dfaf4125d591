// SPDX-License-Identifier: Apache-2.0
// Kernels of the sample points, written once for every SIMD target (sampling.cpp):
//  - the scrambled Sobol points the bakers' rays are made from (sobol_owen_4d_batch below, over
//    core/sampling.h's sobol_reversed_4d_batch): Owen scrambling in bit-reversed order (Laine and
//    Karras 2011, Burley 2020's constants) and the outer reversal, 16 points of 4 dimensions at a
//    time. Integer arithmetic: every target gives the same bits.
//  - the ray-traced reference's directions about a point (reference/raytraced.cpp): its Sobol
//    table, shifted and mapped to the cosine-weighted hemisphere, one packet at a time. Products and
//    sums in one order, none fused: every target gives the same bits.
#pragma once

#include <cstdint>

namespace ao {

/// Points first .. first + count - 1 of sobol_owen_4d(., seed) (core/sampling.h), count in [0, 16]:
/// dimension d of point first + k in out[d][k], bit-identical to sobol_owen_4d. The per-dimension
/// keys are hashed once and the scramble runs over the 16 lanes in SIMD registers (the inside-out
/// baker's rays of one packet).
void sobol_owen_4d_batch(std::uint32_t first, int count, std::uint32_t seed, float (&out)[4][16]);

}  // namespace ao

namespace ao::simd {

/// out[d][k] = to_unit_float(reverse_bits(laine_karras(r[d][k], key[d]))) for the 4 dimensions d
/// and the 16 points k: r holds the points' bit-reversed unscrambled coordinates, key each
/// dimension's scramble seed.
void owen_scramble_4x16(const std::uint32_t (&r)[4][16], const std::uint32_t (&key)[4], float (&out)[4][16]);

/// A point's sample set for cosine_directions: the Sobol table's rows from the packet's first
/// sample on (u0 in [0, 1), cos and sin of 2 pi u1) and the point's frame and shift.
struct CosineSamples {
  const float* u0;
  const float* cos_phi;
  const float* sin_phi;
  float t[3], b[3], n[3];  // tangent frame about the integration normal (rotated by the point's azimuth shift)
  float ng[3];             // unit geometric normal on the side the rays leave from
  float shift;             // Cranley-Patterson shift of u0, [0, 1)
};

/// Directions of samples k in [0, count) (count <= 16, the table holds them): u = u0 + shift mod 1
/// mapped to the unit disk, r = sqrt(u), (x, y) = r (cos phi, sin phi), and lifted to the
/// hemisphere, z = sqrt(1 - u) (Malley's method: cosine-weighted), d = t x + b y + n z. valid[k] =
/// -1 for k < live whose d is above the geometric tangent plane (d . ng > 0), else 0. Returns how
/// many are valid.
int cosine_directions(const CosineSamples& s, int count, int live, float* dir_x, float* dir_y, float* dir_z, int* valid);

}  // namespace ao::simd
