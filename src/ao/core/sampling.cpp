#include "ao/core/sampling.h"

#include <cmath>

namespace ao {

namespace {

std::uint32_t reverse_bits(std::uint32_t x) {
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

// Dimension 1 of Sobol: the direction numbers of the primitive polynomial x + 1,
// v_0 = 2^31, v_{k+1} = v_k ^ (v_k >> 1), XORed over the set bits of the index. The map is linear
// over GF(2), so it is four lookups of 256-entry tables, one per byte of the index.
struct SobolDim1Tables {
  std::uint32_t t[4][256];
  constexpr SobolDim1Tables() : t{} {
    std::uint32_t v[32] = {};
    v[0] = 1u << 31;
    for (int k = 1; k < 32; ++k) v[k] = v[k - 1] ^ (v[k - 1] >> 1);
    for (int byte = 0; byte < 4; ++byte)
      for (std::uint32_t x = 0; x < 256; ++x) {
        std::uint32_t r = 0;
        for (int b = 0; b < 8; ++b)
          if (x >> b & 1u) r ^= v[8 * byte + b];
        t[byte][x] = r;
      }
  }
};
constexpr SobolDim1Tables kSobolDim1{};

std::uint32_t sobol_dim1(std::uint32_t i) {
  return kSobolDim1.t[0][i & 0xffu] ^ kSobolDim1.t[1][(i >> 8) & 0xffu] ^ kSobolDim1.t[2][(i >> 16) & 0xffu] ^ kSobolDim1.t[3][i >> 24];
}

}  // namespace

Vec2 sobol_owen_2d(std::uint32_t index, std::uint32_t seed) {
  // shuffled = nested_uniform_scramble(index); Sobol dimension 0 is the bit reversal of the index
  // (van der Corput), which cancels the inner reversal of its scramble: x = reverse(hash(shuffled)).
  const std::uint32_t shuffled = reverse_bits(laine_karras(reverse_bits(index), hash_combine(seed, 0xa511e9b3u)));
  const std::uint32_t x = reverse_bits(laine_karras(shuffled, hash_combine(seed, 1u)));
  const std::uint32_t y = reverse_bits(laine_karras(reverse_bits(sobol_dim1(shuffled)), hash_combine(seed, 2u)));
  return {to_unit_float(x), to_unit_float(y)};
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
