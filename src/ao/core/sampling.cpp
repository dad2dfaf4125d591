// SPDX-License-Identifier: Apache-2.0
#include "ao/core/sampling.h"

#include <array>
#include <cmath>
#include <initializer_list>


namespace ao {

namespace {

constexpr std::uint32_t reverse_bits(std::uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
  return (x >> 16) | (x << 16);
}

// Owen scrambling in bit-reversed order: a hash in which each bit depends only on lower bits
// (Laine and Karras 2011, with Burley's stronger constants) applied to the reversed value flips
// each digit based on all more significant digits, which is nested uniform scrambling. The hash
// works on the reversed value; nested_uniform_scramble(x) = reverse_bits(laine_karras(reverse_bits(x))).
std::uint32_t laine_karras(std::uint32_t x, std::uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}

// A Sobol dimension is linear over GF(2): point i is the XOR of the direction numbers v_k over the
// set bits k of i. The tables hold that XOR for every byte value at each of the index's four byte
// positions, so a point is four lookups.
struct SobolTables {
  std::uint32_t t[4][256];
  constexpr explicit SobolTables(const std::uint32_t (&v)[32]) : t{} {
    for (int byte = 0; byte < 4; ++byte)
      for (std::uint32_t x = 0; x < 256; ++x) {
        std::uint32_t r = 0;
        for (int b = 0; b < 8; ++b)
          if (x >> b & 1u) r ^= v[8 * byte + b];
        t[byte][x] = r;
      }
  }
  constexpr std::uint32_t operator()(std::uint32_t i) const { return t[0][i & 0xffu] ^ t[1][(i >> 8) & 0xffu] ^ t[2][(i >> 16) & 0xffu] ^ t[3][i >> 24]; }
};

// Direction numbers v_k = m_k 2^(31 - k) of the Sobol dimension with primitive polynomial of
// degree s and inner coefficients a (bit s-2 of a is the coefficient of x^(s-1), ...) and initial
// m_1..m_s, by the recurrence v_k = v_(k-s) ^ (v_(k-s) >> s) ^ XOR_(j=1..s-1) a_j v_(k-j)
// (Bratley and Fox 1988, Algorithm 659).
struct DirectionNumbers {
  std::uint32_t v[32];
  constexpr DirectionNumbers(int s, std::uint32_t a, std::initializer_list<std::uint32_t> m) : v{} {
    int k = 0;
    for (const std::uint32_t mk : m) {
      v[k] = mk << (31 - k);
      ++k;
    }
    for (; k < 32; ++k) {
      std::uint32_t x = v[k - s] ^ (v[k - s] >> s);
      for (int j = 1; j < s; ++j)
        if (a >> (s - 1 - j) & 1u) x ^= v[k - j];
      v[k] = x;
    }
  }
};

// Dimensions 1-3: the primitive polynomials x + 1, x^2 + x + 1 and x^3 + x + 1 with Joe and
// Kuo's initial numbers (new-joe-kuo-6.21201, its dimensions 2-4). Dimension 1's recurrence is
// v_(k+1) = v_k ^ (v_k >> 1).
constexpr SobolTables kSobolDim1{DirectionNumbers(1, 0, {1}).v};
constexpr SobolTables kSobolDim2{DirectionNumbers(2, 1, {1, 3}).v};
constexpr SobolTables kSobolDim3{DirectionNumbers(3, 1, {1, 3, 1}).v};

std::uint32_t sobol_dim1(std::uint32_t i) { return kSobolDim1(i); }

}  // namespace

Vec2 sobol_owen_2d(std::uint32_t index, std::uint32_t seed) {
  // shuffled = nested_uniform_scramble(index); Sobol dimension 0 is the bit reversal of the index
  // (van der Corput), which cancels the inner reversal of its scramble: x = reverse(hash(shuffled)).
  const std::uint32_t shuffled = reverse_bits(laine_karras(reverse_bits(index), hash_combine(seed, 0xa511e9b3u)));
  const std::uint32_t x = reverse_bits(laine_karras(shuffled, hash_combine(seed, 1u)));
  const std::uint32_t y = reverse_bits(laine_karras(reverse_bits(sobol_dim1(shuffled)), hash_combine(seed, 2u)));
  return {to_unit_float(x), to_unit_float(y)};
}

std::array<float, 4> sobol_owen_4d(std::uint32_t index, std::uint32_t seed) {
  // Dimension 0 is the bit reversal of the index, which cancels the scramble's inner reversal.
  const std::array<std::uint32_t, 4> key = sobol_owen_4d_keys(seed);
  const std::uint32_t d0 = reverse_bits(laine_karras(index, key[0]));
  const std::uint32_t d1 = reverse_bits(laine_karras(reverse_bits(kSobolDim1(index)), key[1]));
  const std::uint32_t d2 = reverse_bits(laine_karras(reverse_bits(kSobolDim2(index)), key[2]));
  const std::uint32_t d3 = reverse_bits(laine_karras(reverse_bits(kSobolDim3(index)), key[3]));
  return {to_unit_float(d0), to_unit_float(d1), to_unit_float(d2), to_unit_float(d3)};
}

void sobol_reversed_4d_batch(std::uint32_t first, int count, std::uint32_t (&r)[4][16]) {
  // Dimension 0's reversal is the index itself. A Sobol dimension is linear over GF(2), and so is
  // the reversal: for first a multiple of 16 and k < 16 (disjoint bits), point first + k is point
  // first XOR point k, so one table lookup per dimension serves all 16 lanes.
  static constexpr auto kLow = [] {
    std::array<std::array<std::uint32_t, 16>, 3> t{};
    for (std::uint32_t k = 0; k < 16; ++k) {
      t[0][k] = reverse_bits(kSobolDim1(k));
      t[1][k] = reverse_bits(kSobolDim2(k));
      t[2][k] = reverse_bits(kSobolDim3(k));
    }
    return t;
  }();
  if (first % 16 == 0) {
    const std::uint32_t high[3] = {reverse_bits(kSobolDim1(first)), reverse_bits(kSobolDim2(first)), reverse_bits(kSobolDim3(first))};
    for (int k = 0; k < 16; ++k) {
      r[0][k] = first + static_cast<std::uint32_t>(k);
      for (int d = 0; d < 3; ++d) r[d + 1][k] = high[d] ^ kLow[static_cast<std::size_t>(d)][static_cast<std::size_t>(k)];
    }
  } else {
    for (int k = 0; k < count; ++k) {
      const std::uint32_t i = first + static_cast<std::uint32_t>(k);
      r[0][k] = i;
      r[1][k] = reverse_bits(kSobolDim1(i));
      r[2][k] = reverse_bits(kSobolDim2(i));
      r[3][k] = reverse_bits(kSobolDim3(i));
    }
  }
}

std::array<std::uint32_t, 4> sobol_owen_4d_keys(std::uint32_t seed) {
  return {hash_combine(seed, 0x50b01u), hash_combine(seed, 0x50b02u), hash_combine(seed, 0x50b03u), hash_combine(seed, 0x50b04u)};
}

Vec3 cosine_hemisphere(Vec2 u) {
  // Concentric mapping of the square [-1,1]^2 to the unit disk (area preserving, low distortion).
  const float a = 2.0f * u.x - 1.0f;
  const float b = 2.0f * u.y - 1.0f;
  float r = 0, phi = 0;
  if (a == 0 && b == 0) return {0, 0, 1};
  if (std::abs(a) > std::abs(b)) {
    r = a;
    phi = (kPi / 4) * (b / a);
  } else {
    r = b;
    phi = (kPi / 2) - (kPi / 4) * (a / b);
  }
  const float x = r * std::cos(phi);
  const float y = r * std::sin(phi);
  // Uniform points on the disk projected up to the hemisphere are cosine distributed.
  const float z = std::sqrt(std::max(0.0f, 1.0f - x * x - y * y));
  return {x, y, z};
}

Vec3 uniform_sphere(Vec2 u) {
  const float z = 1.0f - 2.0f * u.x;
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

}  // namespace ao
