// Voxel cone traced AO (Dalla Favera & Celes 2012, sec. III-C). See cone.h for the convention
// (we return V = 1 - the paper's blocked fraction) and voxelize.h for the grid.
#include "ao/methods/cone.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <mutex>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include "ao/core/error.h"
#include "ao/core/parallel.h"
#include "ao/core/sampling.h"
#include "ao/methods/bilateral.h"
#include "ao/methods/cone_pattern_internal.h"

namespace ao {

namespace {

constexpr int kTile = 16;
// A cone stops once its transmittance T <= kOpaque: its remaining spheres can lower T by at most
// kOpaque, so V (the mean over cones) by at most kOpaque = 1e-4, far below an 8-bit step (1/255).
constexpr float kOpaque = 1e-4f;

// Length of [zlo, zhi) (voxel units along the column) covered by solid voxels, counting the two
// end voxels by the part of them inside the range. The paper counts whole bits (Fig. 7); the
// fractional ends remove a bias of up to a voxel per prism, which matters for the small spheres
// near the apex whose chords are a few voxels long.
inline float solid_length(const std::uint64_t* col, int words, int nbits, float zlo, float zhi) {
  zlo = std::max(zlo, 0.0f);
  zhi = std::min(zhi, static_cast<float>(nbits));
  if (!(zhi > zlo)) return 0.0f;
  const int k0 = static_cast<int>(zlo);
  const int k1 = std::min(static_cast<int>(zhi), nbits - 1);
  const auto bit = [&](int k) { return static_cast<float>((col[k >> 6] >> (k & 63)) & 1u); };
  if (k0 >= k1) return bit(k0) * (zhi - zlo);
  // Whole voxels strictly between the end voxels: bitfieldExtract + bitCount of Fig. 7.
  return bit(k0) * (static_cast<float>(k0 + 1) - zlo) + static_cast<float>(count_bits(col, words, k0 + 1, k1)) +
         bit(k1) * (zhi - static_cast<float>(k1));
}

// Obstructed fraction of one sphere (sec. III-C1): prisms along the grid's z through the great
// disk's samples; each prism spans the sphere's chord [z_in, z_out] at its sample. Monte Carlo
// over the disk: volume ~ sum of chords, obstructed volume ~ sum of solid lengths, so the
// fraction is their ratio (as volumetric AO's pipes, the paper's [4]).
struct WorldSampler {
  const VoxelGrid& g;
  Vec3 inv;  // 1 / voxel size along (i, j, k)
  int np;    // prisms per sphere
  int lanes; // np rounded up to a multiple of 8
  // The prisms stay within rho_max of the disk's centre and half_max of the equator (unit disk).
  float rho_max = 0, half_max = 0;
  // Per sphere of the chain (they differ only in radius): radii in voxels along (i, j, k) and the
  // sum of the prisms' chords.
  struct Sphere {
    float rx, ry, rz, chord;
  };
  std::vector<Sphere> spheres;
  // Structure of arrays, padded to `lanes` with zeros: disk points, and per sphere each prism's
  // half chord in voxels ([k * lanes + s]).
  std::vector<float> du, dv, half;

  WorldSampler(const VoxelGrid& grid, const ConeSetup& setup, float r_max)
      : g(grid), inv{1.0f / grid.voxel_size.x, 1.0f / grid.voxel_size.y, 1.0f / grid.voxel_size.z}, np(static_cast<int>(setup.disk.size())),
        lanes((np + 7) / 8 * 8), du(lanes, 0.0f), dv(lanes, 0.0f) {
    for (int s = 0; s < np; ++s) {
      const ConeSetup::Disk& d = setup.disk[s];
      du[s] = d.u, dv[s] = d.v;
      rho_max = std::max(rho_max, std::sqrt(d.u * d.u + d.v * d.v));
      half_max = std::max(half_max, d.half_chord);
    }
    half.assign(setup.sphere_radius.size() * lanes, 0.0f);
    for (std::size_t k = 0; k < setup.sphere_radius.size(); ++k) {
      const float r = setup.sphere_radius[k] * r_max;
      Sphere sp{r * inv.x, r * inv.y, r * inv.z, 0.0f};
      for (int s = 0; s < np; ++s) {
        const float h = setup.disk[s].half_chord * sp.rz;
        half[k * lanes + s] = h;
        sp.chord += 2.0f * h;
      }
      spheres.push_back(sp);
    }
  }

  // Spheres that start nearer the apex than this (world units) are skipped: 1.5 voxels, within
  // which the voxelized surface itself (its staircase on curved and slanted faces, and the surface
  // voxel whose centre is inside) fills them.
  float near_limit() const { return 1.5f * std::max({g.voxel_size.x, g.voxel_size.y, g.voxel_size.z}); }
  // The voxel at world point p (false outside the grid).
  bool solid_at(Vec3 p) const {
    const float gx = (p.x - g.origin.x) * inv.x, gy = (p.z - g.origin.z) * inv.y, gz = (p.y - g.origin.y) * inv.z;
    if (!(gx >= 0 && gy >= 0 && gz >= 0 && gx < g.nx && gy < g.ny && gz < g.depth_bits)) return false;
    return g.voxel(static_cast<int>(gx), static_cast<int>(gy), static_cast<int>(gz));
  }

  // For spheres wider than the largest window: the OR of every block the sphere's box touches.
  bool maybe_solid_blocks(float gx, float gy, float gz, float rx, float ry, float rz) const {
    constexpr float kInvB = 1.0f / VoxelGrid::kBlock;
    const int bx0 = std::max(0, static_cast<int>(std::floor((gx - rx) * kInvB)));
    const int bx1 = std::min(g.bnx - 1, static_cast<int>(std::floor((gx + rx) * kInvB)));
    const int by0 = std::max(0, static_cast<int>(std::floor((gy - ry) * kInvB)));
    const int by1 = std::min(g.bny - 1, static_cast<int>(std::floor((gy + ry) * kInvB)));
    const int k0 = static_cast<int>(std::floor(std::max(gz - rz, -1.0f))), k1 = static_cast<int>(std::min(gz + rz, 1e6f)) + 1;
    for (int by = by0; by <= by1; ++by)
      for (int bx = bx0; bx <= bx1; ++bx)
        if (any_bits(g.block(bx, by), g.words, k0, k1)) return true;
    return false;
  }

  // The disk points turned by (rot_c, rot_s) (the pixel's turn of the prism pattern), into u and v
  // (`lanes` floats each).
  void turn(float rot_c, float rot_s, float* u, float* v) const {
#if defined(__AVX512F__) && defined(__AVX512VL__)
    const __m256 vrc = _mm256_set1_ps(rot_c), vrs = _mm256_set1_ps(rot_s);
    for (int s0 = 0; s0 < lanes; s0 += 8) {
      const __m256 u0 = _mm256_loadu_ps(du.data() + s0), v0 = _mm256_loadu_ps(dv.data() + s0);
      _mm256_storeu_ps(u + s0, _mm256_fmsub_ps(u0, vrc, _mm256_mul_ps(v0, vrs)));
      _mm256_storeu_ps(v + s0, _mm256_fmadd_ps(u0, vrs, _mm256_mul_ps(v0, vrc)));
    }
#else
    for (int s = 0; s < lanes; ++s) u[s] = du[s] * rot_c - dv[s] * rot_s, v[s] = du[s] * rot_s + dv[s] * rot_c;
#endif
  }

  // Obstructed fraction of sphere k of the chain centred at grid point (gx, gy, gz), its radius
  // times `scale` (in (0, 1]: the jittered chain and the filler sphere); (u, v): the disk points
  // in the world x-z plane, turned (turn()).
  float fraction(float gx, float gy, float gz, int k, float scale, const float* u, const float* v) const {
    const Sphere& sp = spheres[k];
    const float* h = half.data() + static_cast<std::size_t>(k) * lanes;
    const float solid = prisms(gx, gy, gz, sp.rx * scale, sp.ry * scale, h, scale, u, v);
    const float chord = sp.chord * scale;
    return chord > 0 ? std::min(1.0f, solid / chord) : 0.0f;
  }

  float scalar_prism(float gx, float gy, float gz, float rx, float ry, float h, float u, float v) const {
    const float fx = gx + u * rx, fy = gy + v * ry;
    if (!(fx >= 0.0f && fy >= 0.0f && fx < static_cast<float>(g.nx) && fy < static_cast<float>(g.ny))) return 0.0f;
    return solid_length(g.column(static_cast<int>(fx), static_cast<int>(fy)), g.words, g.depth_bits, gz - h, gz + h);
  }

#if defined(__AVX512F__) && defined(__AVX512DQ__) && defined(__AVX512VL__) && defined(__AVX512VPOPCNTDQ__) && !defined(AO_NO_GATHER)
  // The solid length of the np prisms summed in prism order, 8 at a time: column indices, z ranges,
  // one gathered 64-bit load per prism starting at the byte that holds its first voxel (bits
  // k0 .. k1 of the column are then bits sh .. sh + k1 - k0 of the load, sh = k0 mod 8, or
  // further in at the column's last 8 bytes), masks and VPOPCNTQ. Prisms longer than the load
  // (k1 - k0 + sh > 63) go the scalar way.
  float prisms(float gx, float gy, float gz, float rx, float ry, const float* h, float scale, const float* pu, const float* pv) const {
    const __m256 vscale = _mm256_set1_ps(scale);
    const __m256 zero = _mm256_setzero_ps(), fnx = _mm256_set1_ps(static_cast<float>(g.nx)), fny = _mm256_set1_ps(static_cast<float>(g.ny));
    const __m256 fbits = _mm256_set1_ps(static_cast<float>(g.depth_bits));
    const __m256i last_bit = _mm256_set1_epi32(g.depth_bits - 1), nx = _mm256_set1_epi32(g.nx), words = _mm256_set1_epi32(g.words);
    const __m256i last_byte = _mm256_set1_epi32(8 * g.words - 8);  // the last 8-byte load that stays in the column
    const __m512i one = _mm512_set1_epi64(1);
    const char* base = reinterpret_cast<const char*>(g.bits.data());
    float solid = 0;
    for (int s0 = 0; s0 < np; s0 += 8) {
      const __mmask8 lane = static_cast<__mmask8>(np - s0 >= 8 ? 0xff : (1u << (np - s0)) - 1);
      const __m256 u = _mm256_loadu_ps(pu + s0), v = _mm256_loadu_ps(pv + s0), hh = _mm256_mul_ps(_mm256_loadu_ps(h + s0), vscale);
      const __m256 fx = _mm256_fmadd_ps(u, _mm256_set1_ps(rx), _mm256_set1_ps(gx)), fy = _mm256_fmadd_ps(v, _mm256_set1_ps(ry), _mm256_set1_ps(gy));
      __m256 zlo = _mm256_sub_ps(_mm256_set1_ps(gz), hh), zhi = _mm256_add_ps(_mm256_set1_ps(gz), hh);
      zlo = _mm256_max_ps(zlo, zero);
      zhi = _mm256_min_ps(zhi, fbits);
      __mmask8 ok = lane & _mm256_cmp_ps_mask(fx, zero, _CMP_GE_OQ) & _mm256_cmp_ps_mask(fy, zero, _CMP_GE_OQ) &
                    _mm256_cmp_ps_mask(fx, fnx, _CMP_LT_OQ) & _mm256_cmp_ps_mask(fy, fny, _CMP_LT_OQ) & _mm256_cmp_ps_mask(zhi, zlo, _CMP_GT_OQ);
      const __m256i ix = _mm256_cvttps_epi32(fx), iy = _mm256_cvttps_epi32(fy);
      const __m256i k0 = _mm256_cvttps_epi32(zlo), k1 = _mm256_min_epi32(_mm256_cvttps_epi32(zhi), last_bit);
      const __m256i byte = _mm256_min_epi32(_mm256_srli_epi32(k0, 3), last_byte);
      const __m256i sh = _mm256_sub_epi32(k0, _mm256_slli_epi32(byte, 3)), n = _mm256_sub_epi32(k1, k0);
      const __mmask8 wide = ok & _mm256_cmp_epi32_mask(_mm256_add_epi32(sh, n), _mm256_set1_epi32(63), _MM_CMPINT_GT);
      ok &= static_cast<__mmask8>(~wide);
      // Byte offsets in 64 bits: a grid of 4096 x 4096 columns of 1024 bits has 2^31 bytes.
      const __m256i col = _mm256_mullo_epi32(_mm256_add_epi32(_mm256_mullo_epi32(iy, nx), ix), words);
      const __m512i at = _mm512_add_epi64(_mm512_slli_epi64(_mm512_cvtepi32_epi64(col), 3), _mm512_cvtepi32_epi64(byte));
      const __m512i word = _mm512_mask_i64gather_epi64(_mm512_setzero_si512(), ok, at, base, 1);
      const __m512i n64 = _mm512_cvtepi32_epi64(n);
      const __m512i x = _mm512_srlv_epi64(word, _mm512_cvtepi32_epi64(sh));  // bit 0 = voxel k0, bit n = voxel k1
      const __m512i bit0 = _mm512_and_si512(x, one), bit1 = _mm512_and_si512(_mm512_srlv_epi64(x, n64), one);
      // Voxels strictly between the end voxels: bits 1 .. n - 1 of x.
      const __m512i mid = _mm512_sub_epi64(_mm512_popcnt_epi64(_mm512_and_si512(x, _mm512_sub_epi64(_mm512_sllv_epi64(one, n64), one))), bit0);
      const __m256 fb0 = _mm512_cvtepi64_ps(bit0), fb1 = _mm512_cvtepi64_ps(bit1), fmid = _mm512_cvtepi64_ps(mid);
      const __m256 fk0 = _mm256_cvtepi32_ps(k0), fk1 = _mm256_cvtepi32_ps(k1);
      // k0 == k1: bit(k0) * (zhi - zlo); else bit(k0) (k0 + 1 - zlo) + between + bit(k1) (zhi - k1).
      const __m256 multi = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(fb0, _mm256_sub_ps(_mm256_add_ps(fk0, _mm256_set1_ps(1.0f)), zlo)), fmid),
                                         _mm256_mul_ps(fb1, _mm256_sub_ps(zhi, fk1)));
      const __m256 single = _mm256_mul_ps(fb0, _mm256_sub_ps(zhi, zlo));
      const __mmask8 one_voxel = _mm256_cmp_epi32_mask(k0, k1, _MM_CMPINT_GE);
      __m256 r = _mm256_maskz_mov_ps(ok, _mm256_mask_blend_ps(one_voxel, multi, single));
      if (wide) {
        alignas(32) float len[8];
        _mm256_store_ps(len, r);
        for (unsigned m = wide; m; m &= m - 1) {
          const int s = s0 + std::countr_zero(m);
          len[s - s0] = scalar_prism(gx, gy, gz, rx, ry, h[s] * scale, pu[s], pv[s]);
        }
        r = _mm256_load_ps(len);
      }
      // Summed lane by lane in prism order (lanes past np hold 0), the order of the scalar path.
      const __m128 lo = _mm256_castps256_ps128(r), hi = _mm256_extractf128_ps(r, 1);
      solid += _mm_cvtss_f32(lo);
      solid += _mm_cvtss_f32(_mm_movehdup_ps(lo));
      solid += _mm_cvtss_f32(_mm_movehl_ps(lo, lo));
      solid += _mm_cvtss_f32(_mm_shuffle_ps(lo, lo, 3));
      solid += _mm_cvtss_f32(hi);
      solid += _mm_cvtss_f32(_mm_movehdup_ps(hi));
      solid += _mm_cvtss_f32(_mm_movehl_ps(hi, hi));
      solid += _mm_cvtss_f32(_mm_shuffle_ps(hi, hi, 3));
    }
    return solid;
  }
#else
  // The solid length of the np prisms summed in prism order.
  float prisms(float gx, float gy, float gz, float rx, float ry, const float* h, float scale, const float* pu, const float* pv) const {
    float solid = 0;
    for (int s = 0; s < np; ++s) solid += scalar_prism(gx, gy, gz, rx, ry, h[s] * scale, pu[s], pv[s]);
    return solid;
  }
#endif
};

struct EyeSampler {
  const VoxelGrid& g;
  float sx, sy, ox, oy;  // camera-space (x/depth, y/depth) -> column coordinates
  const ConeSetup::Disk* disk;
  int np;
  std::vector<float> radius;  // world units, per sphere of the chain

  // As WorldSampler::near_limit, with the voxel of the column the point projects to: its depth
  // 1 / voxels_per_unit and its width at the point's depth.
  float near_limit(Vec3 c) const {
    const float depth = -c.z;
    if (!(depth > 0)) return 0.0f;
    const float fx = c.x / depth * sx + ox, fy = c.y / depth * sy + oy;
    const int i = std::clamp(static_cast<int>(fx), 0, g.nx - 1), j = std::clamp(static_cast<int>(fy), 0, g.ny - 1);
    const float width = depth * std::max(1.0f / std::abs(sx), 1.0f / std::abs(sy));
    return 1.5f * std::max(1.0f / g.voxels_per_unit[static_cast<std::size_t>(j) * g.nx + i], width);
  }

  // The voxel at camera-space point c (false outside the grid).
  bool solid_at(Vec3 c) const {
    const float depth = -c.z;
    if (!(depth > 0)) return false;
    const float fx = c.x / depth * sx + ox, fy = c.y / depth * sy + oy;
    if (!(fx >= 0.0f && fy >= 0.0f && fx < static_cast<float>(g.nx) && fy < static_cast<float>(g.ny))) return false;
    const std::size_t col = static_cast<std::size_t>(static_cast<int>(fy)) * g.nx + static_cast<int>(fx);
    const float k = (depth - g.z_near[col]) * g.voxels_per_unit[col];
    if (!(k >= 0.0f && k < static_cast<float>(g.depth_bits))) return false;
    return g.voxel(static_cast<int>(fx), static_cast<int>(fy), static_cast<int>(k));
  }

  // centre in camera space; the prisms run along the camera's z (the grid's columns are view rays:
  // over one sphere they are close to parallel, the approximation the paper's texture fetch makes).
  float operator()(Vec3 c, int k, float scale, float rot_c, float rot_s) const {
    const float r = radius[k] * scale;
    float solid = 0, chord = 0;
    const float depth = -c.z;
    if (!(depth > 0)) return 0.0f;
    const float inv = 1.0f / depth;
    for (int s = 0; s < np; ++s) {
      const float u = disk[s].u * rot_c - disk[s].v * rot_s, v = disk[s].u * rot_s + disk[s].v * rot_c;
      const float half = disk[s].half_chord * r;
      chord += 2.0f * half;
      const float fx = (c.x + u * r) * inv * sx + ox, fy = (c.y + v * r) * inv * sy + oy;
      if (!(fx >= 0.0f && fy >= 0.0f && fx < static_cast<float>(g.nx) && fy < static_cast<float>(g.ny))) continue;
      const std::size_t col = static_cast<std::size_t>(static_cast<int>(fy)) * g.nx + static_cast<int>(fx);
      const float zn = g.z_near[col], vpu = g.voxels_per_unit[col];
      // eq. 2 for z_in and z_out; the solid length comes back in world units through 1 / vpu.
      solid += solid_length(g.bits.data() + col * g.words, g.words, g.depth_bits, (depth - half - zn) * vpu, (depth + half - zn) * vpu) / vpu;
    }
    return chord > 0 ? std::min(1.0f, solid / chord) : 0.0f;
  }
};

// Per sphere of a cone: where along the axis it sits (world units), which sphere of the chain it
// is (its prisms' half chords) and the scale of its radius. The chain of sphere k is scaled by the
// cone's s: sphere k at s d_k with radius s r_k, starting at s (d_k - r_k). A scaled chain ends at
// s R_max; the filler sphere, inscribed in [s R_max, R_max] along the axis, samples the rest: its
// radius (1 - s) R_max / 2 is at most the last sphere's (equal at s = 1/q), and it fits in the
// cone for s >= 1/q. `used` is false for spheres that start within near_limit of the apex and for
// a filler of (almost) no size.
struct ChainSphere {
  float distance, scale;
  int k;
  bool used;
};
void chain_spheres(const ConeSetup& setup, float r_max, float near, float chain_scale, ChainSphere* out) {
  const int ns = static_cast<int>(setup.sphere_distance.size());
  for (int k = 0; k < ns; ++k) {
    const float start = (setup.sphere_distance[k] - setup.sphere_radius[k]) * r_max * chain_scale;
    out[k] = {setup.sphere_distance[k] * r_max * chain_scale, chain_scale, k, start >= near};
  }
  const float filler = 0.5f * (1.0f - chain_scale) / setup.sphere_radius.back();  // radius / the last sphere's
  out[ns] = {0.5f * (1.0f + chain_scale) * r_max, std::min(filler, 1.0f), ns - 1, filler > 1e-3f};
}

// Front-to-back along one cone (sec. III-C2, Fig. 8): each sphere absorbs its obstructed fraction
// f of the rays that reach it, T *= 1 - f, until T <= kOpaque.
// `inside`: a surface point facing into the winding-number solid counts the complement.
template <class Fraction>
float transmittance(const ChainSphere* chain, int n, bool inside, Fraction&& fraction) {
  float t = 1.0f;
  for (int k = 0; k < n && t > kOpaque; ++k) {
    if (!chain[k].used) continue;
    const float f = fraction(k);
    t *= inside ? f : 1.0f - f;
  }
  return t;
}

// The inside of a holed mesh's shell, seen through a hole, faces into its winding-number solid
// (voxelize.h); its occluders are the inside of the shell, so its cones count the complement of
// the solid as occluded (1 - the obstructed fraction): a hollow inside.
template <class Sampler>
bool faces_inside(const GBuffer& gb, const Sampler& sample, int x, int y, Vec3 p, Vec3 n, float near) {
  const std::uint32_t id = gb.object_id(x, y);
  const std::vector<std::uint8_t>& capped = sample.g.capped;
  return id > 0 && id <= capped.size() && capped[id - 1] && sample.solid_at(p + n * near);
}

// The spheres of one cone in lanes, j < ns being sphere j of its chain and j = ns its filler,
// padded to whole vectors of kLanes with lanes that are never sampled. The chain of a cone with
// scale s has sphere j at s d_j with radius s r_j, starting at s (d_j - r_j); a scaled chain ends
// at s R_max, and the filler sphere, inscribed in [s R_max, R_max] along the axis, samples the
// rest: its radius (1 - s) R_max / 2 is at most the last sphere's (equal at s = 1/q), and it fits
// in the cone for s >= 1/q. So each lane's distance along the axis, radius scale and "is sampled"
// test are affine in s:
//   distance = dist_a s + dist_b, radius scale = min(rad_a s + rad_b, 1), sampled: use_a s + use_b >= 0,
// sampled meaning: the sphere starts at least near_limit from the apex (the chain), the filler's
// radius is more than 1e-3 of the last sphere's.
constexpr int kLanes = 8;
struct ConeLanes {
  int per_cone = 0;
  int padded = 0;  // per_cone rounded up to a multiple of kLanes
  std::vector<float> dist_a, dist_b, rad_a, rad_b, use_a, use_b;
  std::vector<float> ex, ey, ez;  // half extents of the prisms' box at radius scale 1, voxels (PixelSpheres::place_cone)
  std::vector<int> k;             // sphere of the chain whose prisms it uses

  ConeLanes(const ConeSetup& setup, const WorldSampler& sample, float r_max) {
    const int ns = static_cast<int>(setup.sphere_distance.size());
    per_cone = ns + 1;
    padded = (per_cone + kLanes - 1) / kLanes * kLanes;
    const float near = sample.near_limit();
    const float inv_last_radius = 1.0f / setup.sphere_radius.back();  // relative to R_max
    for (int j = 0; j <= ns; ++j) {
      const int kj = std::min(j, ns - 1);
      if (j < ns) {
        dist_a.push_back(setup.sphere_distance[j] * r_max), dist_b.push_back(0.0f);
        rad_a.push_back(1.0f), rad_b.push_back(0.0f);
        use_a.push_back((setup.sphere_distance[j] - setup.sphere_radius[j]) * r_max), use_b.push_back(-near);
      } else {
        dist_a.push_back(0.5f * r_max), dist_b.push_back(0.5f * r_max);
        rad_a.push_back(-0.5f * inv_last_radius), rad_b.push_back(0.5f * inv_last_radius);
        use_a.push_back(-0.5f * inv_last_radius), use_b.push_back(0.5f * inv_last_radius - 1e-3f);
      }
      const WorldSampler::Sphere& sp = sample.spheres[kj];
      ex.push_back(sample.rho_max * sp.rx), ey.push_back(sample.rho_max * sp.ry), ez.push_back(sample.half_max * sp.rz);
      k.push_back(kj);
    }
    for (int j = per_cone; j < padded; ++j) {
      dist_a.push_back(0.0f), dist_b.push_back(0.0f), rad_a.push_back(0.0f), rad_b.push_back(0.0f), use_a.push_back(0.0f), use_b.push_back(-1.0f);
      ex.push_back(0.0f), ey.push_back(0.0f), ez.push_back(0.0f), k.push_back(0);
    }
  }
};

// Bit j set where lane j of v is not zero.
inline std::uint32_t lane_bits(const std::int32_t* v) {
#if defined(__AVX512F__) && defined(__AVX512VL__)
  const __m256i a = _mm256_load_si256(reinterpret_cast<const __m256i*>(v));
  return _mm256_test_epi32_mask(a, a);
#else
  std::uint32_t m = 0;
  for (int j = 0; j < kLanes; ++j) m |= (v[j] != 0 ? 1u : 0u) << j;
  return m;
#endif
}

// The coarse test of kLanes spheres (deviation 6): bit j set where window mask idx[j] has a bit
// among z cells lo[j] .. lo[j] + span[j].
inline std::uint32_t window_bits(const std::uint64_t* win, const std::int32_t* idx, const std::int32_t* lo, const std::int32_t* span) {
#if defined(__AVX512F__) && defined(__AVX512VL__) && !defined(AO_NO_GATHER)
  const __m512i w = _mm512_i32gather_epi64(_mm256_load_si256(reinterpret_cast<const __m256i*>(idx)), reinterpret_cast<const long long*>(win), 8);
  const __m512i l = _mm512_cvtepi32_epi64(_mm256_load_si256(reinterpret_cast<const __m256i*>(lo)));
  const __m512i sh = _mm512_cvtepi32_epi64(_mm256_sub_epi32(_mm256_set1_epi32(63), _mm256_load_si256(reinterpret_cast<const __m256i*>(span))));
  return _mm512_test_epi64_mask(_mm512_srlv_epi64(w, l), _mm512_srlv_epi64(_mm512_set1_epi64(-1), sh));
#else
  std::uint32_t m = 0;
  for (int j = 0; j < kLanes; ++j) m |= (((win[idx[j]] >> lo[j]) & (~std::uint64_t{0} >> (63 - span[j]))) != 0 ? 1u : 0u) << j;
  return m;
#endif
}

#if defined(__AVX512F__) && defined(__AVX512VL__) && defined(__AVX512DQ__) && !defined(AO_NO_GATHER)
// The spheres of all of a pixel's cones in one flat run of slots, i = c * per_cone + j (cone c,
// lane j of ConeLanes), padded to whole vectors with slots that are never sampled: with 6 cones of
// 6 spheres, 5 vectors of 8 instead of 6 half-empty ones per cone. Per slot: its cone and the
// constants of its lane.
struct FlatSlots {
  int n = 0, padded = 0;
  std::vector<std::int32_t> cone;
  std::vector<float> dist_a, dist_b, rad_a, rad_b, use_a, use_b;
  // Half extents of the prisms' box at radius scale 1 with a relative margin of 1e-3 for rounding:
  // x and y in window cells (1 / kCellXY of the voxels; exact powers of two), z in voxels.
  std::vector<float> ex, ey, ez;

  FlatSlots(const ConeLanes& q, int cones) {
    n = cones * q.per_cone;
    padded = (n + kLanes - 1) / kLanes * kLanes;
    constexpr float kInvC = 1.0f / VoxelGrid::kCellXY;
    for (int i = 0; i < padded; ++i) {
      const bool real = i < n;
      const int j = real ? i % q.per_cone : q.padded - 1;  // a padding lane: never sampled
      cone.push_back(real ? i / q.per_cone : 0);
      dist_a.push_back(q.dist_a[j]), dist_b.push_back(q.dist_b[j]), rad_a.push_back(q.rad_a[j]), rad_b.push_back(q.rad_b[j]);
      use_a.push_back(q.use_a[j]), use_b.push_back(real ? q.use_b[j] : -1.0f);
      ex.push_back(q.ex[j] * 1.001f * kInvC), ey.push_back(q.ey[j] * 1.001f * kInvC), ez.push_back(q.ez[j] * 1.001f);
    }
  }
};
#endif

// One pixel's spheres, placed and tested against the coarse masks with no branch between spheres
// (the placement is vector arithmetic; the mask loads are gathers).
struct PixelSpheres {
  // Per slot c * stride + j (cone c, lane j): centre (voxels) and radius scale; bit arrays of
  // "sampled", "wider than the largest window" and the verdict (sampled and the coarse masks say
  // maybe; wide: maybe_solid_blocks decides).
  int stride = 0;
  std::vector<float> cx, cy, cz, rs;
  std::vector<std::uint8_t> used, wide, pass;
  // The pixel, and its prism pattern turned (WorldSampler::turn).
  int x = 0, y = 0;
  bool inside = false;
  std::vector<float> u, v;
  // Per cone (padded to a multiple of 8): chain scale and axis in voxels.
  std::vector<float> scale, ax, ay, az;

  PixelSpheres(int cones, int stride_, int lanes)
      : stride(stride_), cx(static_cast<std::size_t>(cones) * stride + kLanes), cy(cx.size()), cz(cx.size()), rs(cx.size()),
        used(cx.size() / 8 + 8), wide(used.size()), pass(used.size()), u(lanes), v(lanes), scale((cones + 7) / 8 * 8), ax(scale.size()),
        ay(scale.size()), az(scale.size()) {}

  // `count` (<= 25) bits of a bit array from bit `first`.
  static std::uint32_t bits(const std::vector<std::uint8_t>& b, int first, int count) {
    std::uint32_t word;
    std::memcpy(&word, b.data() + (first >> 3), sizeof word);
    return (word >> (first & 7)) & ((1u << count) - 1);
  }
  static bool bit(const std::vector<std::uint8_t>& b, int i) { return (b[static_cast<std::size_t>(i) >> 3] >> (i & 7)) & 1u; }

  // Cone c (axis and scale from ax[c], ...) from the grid point (gx, gy, gz), stride = q.padded.
  void place_cone(const ConeLanes& q, const WorldSampler& sample, int c, float gx, float gy, float gz) {
    const int dnx = sample.g.dnx, dny = sample.g.dny, cap = VoxelGrid::kWindowCap, shift = sample.g.cell_shift;
    const float fdnx = static_cast<float>(dnx - 1), fdny = static_cast<float>(dny - 1), fbits = static_cast<float>(sample.g.depth_bits - 1);
    constexpr float kInvC = 1.0f / VoxelGrid::kCellXY;
    const float s = scale[c], cax = ax[c], cay = ay[c], caz = az[c];
    for (int j0 = 0; j0 < q.padded; j0 += kLanes) {
      alignas(32) std::int32_t use[kLanes], idx[kLanes], lo[kLanes], span[kLanes], wid[kLanes];
      const float *__restrict da = q.dist_a.data() + j0, *__restrict db = q.dist_b.data() + j0, *__restrict ra = q.rad_a.data() + j0,
                              *__restrict rb = q.rad_b.data() + j0;
      const float *__restrict ua = q.use_a.data() + j0, *__restrict ub = q.use_b.data() + j0;
      const float *__restrict qex = q.ex.data() + j0, *__restrict qey = q.ey.data() + j0, *__restrict qez = q.ez.data() + j0;
      const std::size_t i0 = static_cast<std::size_t>(c) * q.padded + j0;
      float *__restrict ox = cx.data() + i0, *__restrict oy = cy.data() + i0, *__restrict oz = cz.data() + i0, *__restrict orr = rs.data() + i0;
#pragma GCC ivdep  // the arrays do not overlap (GCC does not apply __restrict to local pointers)
      for (int j = 0; j < kLanes; ++j) {
        const float d = da[j] * s + db[j];
        const float px = gx + cax * d, py = gy + cay * d, pz = gz + caz * d;
        const float r = std::min(ra[j] * s + rb[j], 1.0f);
        ox[j] = px, oy[j] = py, oz[j] = pz, orr[j] = r;
        use[j] = ua[j] * s + ub[j] >= 0.0f ? 1 : 0;
        // Empty-space skipping (not in the paper; exact: a skipped sphere's prisms read no solid
        // voxel). The sphere's prisms read columns within (ex, ey) = rho_max * (rx, ry) of its
        // centre and voxels within ez = half_max * rz along them (floor(a) - floor(a - b) <=
        // ceil(b); the margins cover rounding). That box of columns lies in the window (voxelize.h)
        // anchored at its lowest cell, w = its larger span in cells (clamped into the grid, which
        // only drops columns no prism can read); window_bits checks the window's z cells cl..ch. A
        // box wider than the largest window goes to maybe_solid_blocks. Indices are
        // int(min(max(0, x), n - 1)): clamp(floor(x), 0, n - 1) for x >= 0, and 0 for NaN.
        const float ex = qex[j] * r * 1.001f + 1e-3f, ey = qey[j] * r * 1.001f + 1e-3f, ez = qez[j] * r * 1.001f + 1e-3f;
        const int x0 = static_cast<int>(std::min(std::max(0.0f, (px - ex) * kInvC), fdnx)), x1 = static_cast<int>(std::min(std::max(0.0f, (px + ex) * kInvC), fdnx));
        const int y0 = static_cast<int>(std::min(std::max(0.0f, (py - ey) * kInvC), fdny)), y1 = static_cast<int>(std::min(std::max(0.0f, (py + ey) * kInvC), fdny));
        const int w = std::max(x1 - x0, y1 - y0);
        const int cl = static_cast<int>(std::min(std::max(0.0f, pz - ez), fbits)) >> shift, ch = static_cast<int>(std::min(std::max(0.0f, pz + ez), fbits)) >> shift;
        idx[j] = (y0 * dnx + x0) * (cap + 1) + std::min(w, cap);
        lo[j] = cl, span[j] = ch - cl, wid[j] = w > cap ? 1 : 0;
      }
      const std::uint32_t u_bits = lane_bits(use), w_bits = lane_bits(wid);
      used[i0 >> 3] = static_cast<std::uint8_t>(u_bits), wide[i0 >> 3] = static_cast<std::uint8_t>(w_bits);
      pass[i0 >> 3] = static_cast<std::uint8_t>(u_bits & (window_bits(sample.g.window.data(), idx, lo, span) | w_bits));
    }
  }

#if defined(__AVX512F__) && defined(__AVX512VL__) && defined(__AVX512DQ__) && !defined(AO_NO_GATHER)
  // Every slot of `q` (stride = per_cone): the same placement and test as place_cone, 8 slots at a
  // time, each slot taking its cone's scale and axis by a permutation (a gather past 8 cones).
  void place_flat(const FlatSlots& q, const WorldSampler& sample, int cones, float gx, float gy, float gz) {
    const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f), quarter = _mm256_set1_ps(1.0f / VoxelGrid::kCellXY);
    const __m256 fdnx = _mm256_set1_ps(static_cast<float>(sample.g.dnx - 1)), fdny = _mm256_set1_ps(static_cast<float>(sample.g.dny - 1));
    const __m256 fbits = _mm256_set1_ps(static_cast<float>(sample.g.depth_bits - 1));
    const __m256 margin_c = _mm256_set1_ps(1e-3f / VoxelGrid::kCellXY), margin_z = _mm256_set1_ps(1e-3f);
    const __m256 vgx = _mm256_set1_ps(gx), vgy = _mm256_set1_ps(gy), vgz = _mm256_set1_ps(gz);
    const __m256i dnx = _mm256_set1_epi32(sample.g.dnx), cap = _mm256_set1_epi32(VoxelGrid::kWindowCap), c63 = _mm256_set1_epi32(63);
    const __m128i shift = _mm_cvtsi32_si128(sample.g.cell_shift);
    const __m512i ones = _mm512_set1_epi64(-1);
    const long long* win = reinterpret_cast<const long long*>(sample.g.window.data());
    const __m256 vs = _mm256_loadu_ps(scale.data()), vax = _mm256_loadu_ps(ax.data()), vay = _mm256_loadu_ps(ay.data()), vaz = _mm256_loadu_ps(az.data());
    for (int i = 0; i < q.padded; i += kLanes) {
      const __m256i c = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(q.cone.data() + i));
      __m256 s, cax, cay, caz;
      if (cones <= kLanes) {
        s = _mm256_permutexvar_ps(c, vs), cax = _mm256_permutexvar_ps(c, vax), cay = _mm256_permutexvar_ps(c, vay), caz = _mm256_permutexvar_ps(c, vaz);
      } else {
        s = _mm256_i32gather_ps(scale.data(), c, 4), cax = _mm256_i32gather_ps(ax.data(), c, 4), cay = _mm256_i32gather_ps(ay.data(), c, 4),
        caz = _mm256_i32gather_ps(az.data(), c, 4);
      }
      const __m256 d = _mm256_fmadd_ps(_mm256_loadu_ps(q.dist_a.data() + i), s, _mm256_loadu_ps(q.dist_b.data() + i));
      const __m256 px = _mm256_fmadd_ps(cax, d, vgx), py = _mm256_fmadd_ps(cay, d, vgy), pz = _mm256_fmadd_ps(caz, d, vgz);
      const __m256 r = _mm256_min_ps(_mm256_fmadd_ps(_mm256_loadu_ps(q.rad_a.data() + i), s, _mm256_loadu_ps(q.rad_b.data() + i)), one);
      _mm256_storeu_ps(cx.data() + i, px), _mm256_storeu_ps(cy.data() + i, py), _mm256_storeu_ps(cz.data() + i, pz), _mm256_storeu_ps(rs.data() + i, r);
      const __mmask8 use = _mm256_cmp_ps_mask(_mm256_fmadd_ps(_mm256_loadu_ps(q.use_a.data() + i), s, _mm256_loadu_ps(q.use_b.data() + i)), zero, _CMP_GE_OQ);
      // The box of place_cone in cells (x, y) and voxels (z); max(v, 0) gives 0 for NaN.
      const __m256 ex = _mm256_fmadd_ps(_mm256_loadu_ps(q.ex.data() + i), r, margin_c), ey = _mm256_fmadd_ps(_mm256_loadu_ps(q.ey.data() + i), r, margin_c);
      const __m256 ez = _mm256_fmadd_ps(_mm256_loadu_ps(q.ez.data() + i), r, margin_z);
      const __m256 pxc = _mm256_mul_ps(px, quarter), pyc = _mm256_mul_ps(py, quarter);
      const auto cell = [&](__m256 a, __m256 hi) { return _mm256_cvttps_epi32(_mm256_min_ps(_mm256_max_ps(a, zero), hi)); };
      const __m256i x0 = cell(_mm256_sub_ps(pxc, ex), fdnx), x1 = cell(_mm256_add_ps(pxc, ex), fdnx);
      const __m256i y0 = cell(_mm256_sub_ps(pyc, ey), fdny), y1 = cell(_mm256_add_ps(pyc, ey), fdny);
      const __m256i cl = _mm256_sra_epi32(cell(_mm256_sub_ps(pz, ez), fbits), shift), ch = _mm256_sra_epi32(cell(_mm256_add_ps(pz, ez), fbits), shift);
      const __m256i w = _mm256_max_epi32(_mm256_sub_epi32(x1, x0), _mm256_sub_epi32(y1, y0));
      const __mmask8 wid = _mm256_cmp_epi32_mask(w, cap, _MM_CMPINT_GT);
      const __m256i idx = _mm256_add_epi32(_mm256_slli_epi32(_mm256_add_epi32(_mm256_mullo_epi32(y0, dnx), x0), 3), _mm256_min_epi32(w, cap));
      const __m512i wm = _mm512_i32gather_epi64(idx, win, 8);
      const __m512i sh = _mm512_cvtepi32_epi64(_mm256_sub_epi32(c63, _mm256_sub_epi32(ch, cl)));
      const __mmask8 any = _mm512_test_epi64_mask(_mm512_srlv_epi64(wm, _mm512_cvtepi32_epi64(cl)), _mm512_srlv_epi64(ones, sh));
      used[i >> 3] = use, wide[i >> 3] = wid, pass[i >> 3] = use & (any | wid);
    }
  }
#endif
};

// World grid: per pixel, every sphere is placed and passes the coarse test (PixelSpheres), then
// each cone runs front to back, sampling the prisms of the spheres that passed.
void trace_world(const GBuffer& gb, const WorldSampler& sample, float r_max, const ConeSetup& setup, const ConePattern& pat, ImageView<float> out,
                 const ProgressFn& progress) {
  const int w = gb.width(), h = gb.height();
  const Frame basis = gb.camera.basis();
  const Vec3 eye = gb.camera.eye;
  const VoxelGrid& g = sample.g;
  const Vec3 inv = sample.inv;
  const int nc = pat.cones;
  const ConeLanes lanes(setup, sample, r_max);
  const int per_cone = lanes.per_cone;
#if defined(__AVX512F__) && defined(__AVX512VL__) && defined(__AVX512DQ__) && !defined(AO_NO_GATHER)
  const FlatSlots flat(lanes, nc);
  const int stride = per_cone;
  // The pattern's cone axes and chain scales per slot, cones padded to 8 (zeros).
  const int cones_padded = (nc + 7) / 8 * 8;
  struct {
    std::vector<float> x, y, z, s;
  } soa;
  for (auto* a : {&soa.x, &soa.y, &soa.z, &soa.s}) a->assign(pat.cone.size() / nc * cones_padded, 0.0f);
  for (std::size_t slot = 0; slot < pat.cone.size() / nc; ++slot)
    for (int c = 0; c < nc; ++c) {
      const ConePattern::Cone& k = pat.cone[slot * nc + c];
      const std::size_t o = slot * cones_padded + c;
      soa.x[o] = k.x, soa.y[o] = k.y, soa.z[o] = k.z, soa.s[o] = k.scale;
    }
#else
  const int stride = lanes.padded;
#endif
  const float weight = 1.0f / static_cast<float>(nc);  // every cone stands for a cell of equal measure
  const float near = sample.near_limit();
  // Front to back along each cone (sec. III-C2, Fig. 8): each sphere absorbs its obstructed
  // fraction f of the rays that reach it, T *= 1 - f, until T <= kOpaque.
  const auto finish = [&](PixelSpheres& ps) {
    const auto fraction = [&](int i, int j) {
      const int k = lanes.k[j];
      const WorldSampler::Sphere& sp = sample.spheres[k];
      const float r = ps.rs[i];
      if (PixelSpheres::bit(ps.wide, i) && !sample.maybe_solid_blocks(ps.cx[i], ps.cy[i], ps.cz[i], sp.rx * r, sp.ry * r, sp.rz * r)) return 0.0f;
      return sample.fraction(ps.cx[i], ps.cy[i], ps.cz[i], k, r, ps.u.data(), ps.v.data());
    };
    float v = 0;
    for (int c = 0; c < nc; ++c) {
      float tr = 1.0f;
      const int i0 = c * stride;
      if (!ps.inside) {
        // A sphere that failed the coarse test has f = 0 and leaves T as it is: only the passed
        // ones, in order (bit j: sphere j of the cone).
        for (std::uint32_t m = PixelSpheres::bits(ps.pass, i0, per_cone); m && tr > kOpaque; m &= m - 1) {
          const int j = std::countr_zero(m);
          tr *= 1.0f - fraction(i0 + j, j);
        }
      } else {
        // The inside of a shell counts the complement (faces_inside): T *= f, and an empty sphere
        // (f = 0) closes the cone.
        for (int j = 0; j < per_cone && tr > kOpaque; ++j)
          if (PixelSpheres::bit(ps.used, i0 + j)) tr *= PixelSpheres::bit(ps.pass, i0 + j) ? fraction(i0 + j, j) : 0.0f;
      }
      v += weight * tr;
    }
    out(ps.x, ps.y) = std::clamp(v, 0.0f, 1.0f);
  };
  ProgressCounter counter(progress, static_cast<std::size_t>(w) * h);
  parallel_for_tiles(w, h, kTile, [&](const Tile& t) {
    PixelSpheres ps(nc, stride, sample.lanes);
    for (int y = t.y0; y < t.y1; ++y)
      for (int x = t.x0; x < t.x1; ++x) {
        if (!gb.covered(x, y)) {
          out(x, y) = 1.0f;
          continue;
        }
        const Vec3 pos = basis.to_world(gb.position(x, y)) + eye, n = normalize(basis.to_world(gb.normal(x, y)));
        const Frame frame = Frame::from_normal(n);
        ps.x = x, ps.y = y;
        ps.inside = faces_inside(gb, sample, x, y, pos, n, near);
        const int slot = pat.slot(x, y);
        sample.turn(pat.rot[2 * slot], pat.rot[2 * slot + 1], ps.u.data(), ps.v.data());
#if defined(__AVX512F__) && defined(__AVX512VL__) && defined(__AVX512DQ__) && !defined(AO_NO_GATHER)
        // The cones' axes turned into the normal's frame and into voxels, 8 cones at a time.
        {
          const std::size_t o = static_cast<std::size_t>(slot) * cones_padded;
          const __m256 tx = _mm256_set1_ps(frame.t.x), ty = _mm256_set1_ps(frame.t.y), tz = _mm256_set1_ps(frame.t.z);
          const __m256 bx = _mm256_set1_ps(frame.b.x), by = _mm256_set1_ps(frame.b.y), bz = _mm256_set1_ps(frame.b.z);
          const __m256 nx = _mm256_set1_ps(frame.n.x), ny = _mm256_set1_ps(frame.n.y), nz = _mm256_set1_ps(frame.n.z);
          for (int c = 0; c < nc; c += 8) {
            const __m256 lx = _mm256_loadu_ps(soa.x.data() + o + c), ly = _mm256_loadu_ps(soa.y.data() + o + c), lz = _mm256_loadu_ps(soa.z.data() + o + c);
            const __m256 wx = _mm256_fmadd_ps(nx, lz, _mm256_fmadd_ps(bx, ly, _mm256_mul_ps(tx, lx)));
            const __m256 wy = _mm256_fmadd_ps(ny, lz, _mm256_fmadd_ps(by, ly, _mm256_mul_ps(ty, lx)));
            const __m256 wz = _mm256_fmadd_ps(nz, lz, _mm256_fmadd_ps(bz, ly, _mm256_mul_ps(tz, lx)));
            _mm256_storeu_ps(ps.scale.data() + c, _mm256_loadu_ps(soa.s.data() + o + c));
            _mm256_storeu_ps(ps.ax.data() + c, _mm256_mul_ps(wx, _mm256_set1_ps(inv.x)));
            _mm256_storeu_ps(ps.ay.data() + c, _mm256_mul_ps(wz, _mm256_set1_ps(inv.y)));
            _mm256_storeu_ps(ps.az.data() + c, _mm256_mul_ps(wy, _mm256_set1_ps(inv.z)));
          }
        }
#else
        const ConePattern::Cone* cones = pat.cone.data() + static_cast<std::size_t>(slot) * nc;
        for (int c = 0; c < nc; ++c) {
          const Vec3 a = frame.to_world({cones[c].x, cones[c].y, cones[c].z});
          ps.scale[c] = cones[c].scale, ps.ax[c] = a.x * inv.x, ps.ay[c] = a.z * inv.y, ps.az[c] = a.y * inv.z;  // the axis in voxels
        }
#endif
        const float gx = (pos.x - g.origin.x) * inv.x, gy = (pos.z - g.origin.z) * inv.y, gz = (pos.y - g.origin.y) * inv.z;
#if defined(__AVX512F__) && defined(__AVX512VL__) && defined(__AVX512DQ__) && !defined(AO_NO_GATHER)
        ps.place_flat(flat, sample, nc, gx, gy, gz);
#else
        for (int c = 0; c < nc; ++c) ps.place_cone(lanes, sample, c, gx, gy, gz);
#endif
        finish(ps);
      }
    counter.add(static_cast<std::size_t>(t.x1 - t.x0) * (t.y1 - t.y0));
  });
}

// Eye grid: cone by cone, sphere by sphere.
void trace_eye(const GBuffer& gb, const EyeSampler& sample, float r_max, const ConeSetup& setup, const ConePattern& pat, ImageView<float> out,
               const ProgressFn& progress) {
  const int w = gb.width(), h = gb.height();
  const int nc = pat.cones, per_cone = static_cast<int>(setup.sphere_distance.size()) + 1;
  const float weight = 1.0f / static_cast<float>(nc);
  ProgressCounter counter(progress, static_cast<std::size_t>(w) * h);
  parallel_for_tiles(w, h, kTile, [&](const Tile& t) {
    std::vector<ChainSphere> chain(per_cone);
    for (int y = t.y0; y < t.y1; ++y)
      for (int x = t.x0; x < t.x1; ++x) {
        if (!gb.covered(x, y)) {
          out(x, y) = 1.0f;
          continue;
        }
        const Vec3 pos = gb.position(x, y), n = gb.normal(x, y);
        const Frame frame = Frame::from_normal(n);
        const float near = sample.near_limit(pos);
        const bool inside = faces_inside(gb, sample, x, y, pos, n, near);
        const int slot = pat.slot(x, y);
        const float rot_c = pat.rot[2 * slot], rot_s = pat.rot[2 * slot + 1];
        float v = 0;
        for (int c = 0; c < nc; ++c) {
          const ConePattern::Cone& cone = pat.cone[static_cast<std::size_t>(slot) * nc + c];
          chain_spheres(setup, r_max, near, cone.scale, chain.data());
          const Vec3 axis = frame.to_world({cone.x, cone.y, cone.z});
          v += weight * transmittance(chain.data(), per_cone, inside,
                                      [&](int k) { return sample(pos + axis * chain[k].distance, chain[k].k, chain[k].scale, rot_c, rot_s); });
        }
        out(x, y) = std::clamp(v, 0.0f, 1.0f);
      }
    counter.add(static_cast<std::size_t>(t.x1 - t.x0) * (t.y1 - t.y0));
  });
}

}  // namespace

ConeParams cone_preset(ConeQuality q) {
  ConeParams p;
  p.preset = q;
  p.cones = 6;  // Table I fixes 6 cones for every setting
  p.spheres = q == ConeQuality::Low ? 3 : q == ConeQuality::Medium ? 5 : 7;
  p.prisms = q == ConeQuality::Low ? 3 : q == ConeQuality::Medium ? 6 : 12;
  return p;
}

ConeParams ConeParams::resolved() const {
  ConeParams r = *this;
  const ConeParams preset_counts = cone_preset(preset);
  if (!r.cones) r.cones = preset_counts.cones;
  if (!r.spheres) r.spheres = preset_counts.spheres;
  if (!r.prisms) r.prisms = preset_counts.prisms;
  return r;
}

VoxelizeOptions ConeParams::voxelize_options(float r_max) const { return {columns, depth_bits, open_meshes, slab_fraction * r_max}; }

const ParamTable<ConeParams>& cone_param_table() {
  using P = Param<ConeParams>;
  static const ParamTable<ConeParams> table{
      "cone",
      {P::enumeration<ConeQuality>("preset", &ConeParams::preset, {{"low", ConeQuality::Low}, {"medium", ConeQuality::Medium}, {"high", ConeQuality::High}},
                                   "Table I; fills cones, spheres, prisms left null"),
       P::optional_integer("cones", &ConeParams::cones, Range::closed(1, 64), "", "cones per pixel; null = from the preset (6)"),
       P::optional_integer("spheres", &ConeParams::spheres, Range::closed(1, 16), "", "spheres per cone; null = from the preset (3/5/7)"),
       P::optional_integer("prisms", &ConeParams::prisms, Range::closed(1, 64), "", "prisms per sphere; null = from the preset (3/6/12)"),
       P::real("aperture_deg", &ConeParams::aperture_deg, Range::open(0, 90), "degrees", "full apex angle of each cone (sec. III-C: 30)"),
       P::integer("depth_bits", &ConeParams::depth_bits, Range::closed(32, 1024), "", "voxels per grid column, a multiple of 32 (paper: 128)"),
       P::integer("columns", &ConeParams::columns, Range::closed(8, 4096), "", "grid columns per side (world) or along the longer image side (eye)"),
       P::enumeration<GridSpace>("grid", &ConeParams::grid, {{"world", GridSpace::World}, {"eye", GridSpace::Eye}}, "world grid, or the paper's eye-space grid"),
       P::enumeration<ConeWeighting>("weighting", &ConeParams::weighting, {{"cosine", ConeWeighting::Cosine}, {"uniform", ConeWeighting::Uniform}},
                                     "cone cells of equal cosine-weighted measure or of equal solid angle"),
       P::enumeration<OpenMeshes>("open_meshes", &ConeParams::open_meshes,
                                  {{"winding", OpenMeshes::Winding}, {"slab", OpenMeshes::Slab}, {"parity", OpenMeshes::Parity}},
                                  "open meshes: the generalized-winding-number solid, slabs behind their front faces, or parity as the paper"),
       P::real("slab_fraction", &ConeParams::slab_fraction, Range::open_closed(0, 16), "R_max", "thickness of the slab behind open meshes"),
       P::boolean("jitter", &ConeParams::jitter, "per pixel: random cone axes in their cells, sphere-chain scale, prism turn (noise instead of rings)"),
       P::integer("filter_taps", &ConeParams::filter_taps, Range::closed(1, 63), "", "taps per pass of the cross-bilateral filter on V, odd; 1 = no filter")}};
  return table;
}

void ConeParams::validate() const {
  cone_param_table().validate(*this);
  if (filter_taps % 2 == 0) throw InputError("cone: filter_taps must be odd (1 = no filter), got " + std::to_string(filter_taps));
  voxelize_options(1.0f).validate();
}

void to_json(nlohmann::json& j, const ConeParams& p) { j = cone_param_table().to_json(p); }
void from_json(const nlohmann::json& j, ConeParams& p) { cone_param_table().from_json(j, p); }

ConeSetup derive_cone_setup(const ConeParams& p) {
  ConeSetup s;
  const float alpha = 0.5f * p.aperture_deg * kPi / 180.0f;  // half-angle of the cone
  const float sa = std::sin(alpha);

  // Cones: one at the normal, then rings of 5, 11, 17, ... about it, placed regularly in
  // spherical coordinates (sec. III-C, Fig. 5a). Each cone owns a cell of 1/n of the hemisphere's
  // measure: cosine-weighted (s = sin^2 theta is uniform in that measure) or solid angle
  // (1 - cos theta is uniform). Its axis sits at the middle of its ring's band of that measure,
  // but never lower than 90 deg - alpha, so the cone stays above the tangent plane.
  const int n = p.cones.value_or(6);
  std::vector<int> rings{1};
  for (int left = n - 1, cap = 5; left > 0; cap += 6) {
    rings.push_back(std::min(left, cap));
    left -= rings.back();
  }
  int before = 0;
  for (std::size_t ri = 0; ri < rings.size(); ++ri) {
    const float f0 = static_cast<float>(before) / n, f1 = static_cast<float>(before + rings[ri]) / n;
    float theta = 0;
    if (ri > 0) {
      const float mid = 0.5f * (f0 + f1);
      theta = p.weighting == ConeWeighting::Cosine ? std::asin(std::sqrt(mid)) : std::acos(1.0f - mid);
    }
    theta = std::min(theta, 0.5f * kPi - alpha);
    const float dphi = 2.0f * kPi / static_cast<float>(rings[ri]);
    for (int k = 0; k < rings[ri]; ++k) {
      // Odd rings are turned by half a step so that cones of neighbouring rings interleave.
      const float phi = dphi * (static_cast<float>(k) + 0.5f * static_cast<float>(ri % 2));
      s.cones.push_back({std::sin(theta), std::cos(theta), std::cos(phi), std::sin(phi), f0, f1, phi - 0.5f * dphi, dphi});
    }
    before += rings[ri];
  }
  s.sin_theta_max = std::cos(alpha);
  s.cosine = p.weighting == ConeWeighting::Cosine;

  // Sphere chain (Fig. 5b): a sphere at distance d from the apex, inscribed in a cone of
  // half-angle alpha, has radius r = d sin(alpha); tangency of neighbours,
  // d_{k+1} - r_{k+1} = d_k + r_k, gives d_{k+1} = d_k (1 + sin a) / (1 - sin a). The last sphere
  // ends at R_max: d_{K-1} (1 + sin a) = R_max. The first sphere then starts at
  // d_0 (1 - sin a) > 0, clear of the surface at the apex.
  const float q = (1.0f + sa) / (1.0f - sa);
  s.chain_ratio = q;
  const int K = p.spheres.value_or(5);
  s.sphere_distance.resize(K);
  s.sphere_radius.resize(K);
  float d = 1.0f / (1.0f + sa);
  for (int k = K - 1; k >= 0; --k) {
    s.sphere_distance[k] = d;
    s.sphere_radius[k] = d * sa;
    d /= q;
  }
  {
    // The point sets depend on n alone; the Lloyd relaxation costs about a millisecond, per frame
    // otherwise.
    static std::mutex mutex;
    static std::map<int, std::vector<ConeSetup::Disk>> cache;
    const int n_prisms = p.prisms.value_or(6);
    const std::lock_guard<std::mutex> lock(mutex);
    auto it = cache.find(n_prisms);
    if (it == cache.end()) it = cache.emplace(n_prisms, cone_disk_points(n_prisms)).first;
    s.disk = it->second;
  }
  return s;
}

void compute_cone(const GBuffer& gb, const VoxelGrid& g, float r_max, const ConeParams& params, std::uint32_t seed, ImageView<float> out,
                  const ProgressFn& progress) {
  params.validate();
  if (!params.cones || !params.spheres || !params.prisms) throw InputError("cone: compute_cone needs resolved parameters");
  if (!(r_max > 0.0f) || !std::isfinite(r_max)) throw InputError("cone: R_max must be a finite number > 0");
  if (out.width != gb.width() || out.height != gb.height()) throw InputError("cone: output and G-buffer sizes differ");
  const ConeSetup setup = derive_cone_setup(params);
  const ConePattern pattern = make_cone_pattern(setup, params.jitter, seed);
  if (g.space == GridSpace::World) {
    trace_world(gb, WorldSampler(g, setup, r_max), r_max, setup, pattern, out, progress);
  } else {
    const Camera& cam = g.camera;
    const float t = cam.tan_half_fov();
    EyeSampler s{g, 0.5f * cam.width / (t * cam.aspect()) / g.pixels_per_column_x, -0.5f * cam.height / t / g.pixels_per_column_y,
                 0.5f * cam.width / g.pixels_per_column_x, 0.5f * cam.height / g.pixels_per_column_y, setup.disk.data(),
                 static_cast<int>(setup.disk.size()), {}};
    for (float rk : setup.sphere_radius) s.radius.push_back(rk * r_max);
    trace_eye(gb, s, r_max, setup, pattern, out, progress);
  }
}

namespace {

double ms_between(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

ConeParams checked_resolved(const ConeParams& params, float r_max) {
  const ConeParams p = params.resolved();
  p.validate();
  if (!(r_max > 0.0f) || !std::isfinite(r_max)) throw InputError("cone: R_max must be a finite number > 0");
  return p;
}

VoxelGrid voxelize(const Scene& scene, std::span<const MeshClosure> closure, const GBuffer& gb, const ConeParams& p, float r_max, VoxelStats* stats) {
  return p.grid == GridSpace::World ? voxelize_world(scene, closure, p.voxelize_options(r_max), stats)
                                    : voxelize_eye(scene, closure, gb, p.voxelize_options(r_max), stats);
}

// The kernel and the filter on a built grid; `p` resolved and checked.
void trace_and_filter(const GBuffer& gb, const VoxelGrid& g, float r_max, const ConeParams& p, std::uint32_t seed, const ProgressFn& progress,
                      ConeResult& r) {
  using Clock = std::chrono::steady_clock;
  const auto t1 = Clock::now();
  r.visibility = Image<float>(gb.width(), gb.height(), 1.0f);
  compute_cone(gb, g, r_max, p, seed, r.visibility.view(), progress);
  const auto t2 = Clock::now();
  if (p.filter_taps > 1) {
    BilateralParams f;
    f.taps = p.filter_taps;
    bilateral_filter(gb, r.visibility, f);
  }
  r.trace_ms = ms_between(t1, t2);
  r.filter_ms = ms_between(t2, Clock::now());
  r.grid_nx = g.nx;
  r.grid_ny = g.ny;
}

}  // namespace

ConeResult render_cone(const Scene& scene, std::span<const MeshClosure> closure, const GBuffer& gb, float r_max, const ConeParams& params,
                       std::uint32_t seed, const ProgressFn& progress) {
  const ConeParams p = checked_resolved(params, r_max);
  ConeResult r;
  const auto t0 = std::chrono::steady_clock::now();
  const VoxelGrid g = voxelize(scene, closure, gb, p, r_max, &r.voxel_stats);
  r.voxelize_ms = ms_between(t0, std::chrono::steady_clock::now());
  trace_and_filter(gb, g, r_max, p, seed, progress, r);
  return r;
}

ConeContext::ConeContext(const Scene& scene) : scene_(scene), closure_(analyze_closure(scene)) {}

bool ConeContext::grid_is_current(const GBuffer& gb, GridSpace space, const VoxelizeOptions& o) const {
  if (!valid_ || grid_.space != space || o.columns != options_.columns || o.depth_bits != options_.depth_bits ||
      o.open_meshes != options_.open_meshes || o.slab_thickness != options_.slab_thickness)
    return false;
  if (space == GridSpace::World) return true;
  const Camera& c = gb.camera;
  if (!(c.eye == camera_.eye && c.target == camera_.target && c.up == camera_.up && c.vertical_fov_deg == camera_.vertical_fov_deg &&
        c.width == camera_.width && c.height == camera_.height && gb.object_id.size() == depth_.size() && depth_.size() == coverage_.size()))
    return false;
  for (std::size_t i = 0; i < depth_.size(); ++i)
    if (gb.depth(i) != depth_[i] || (gb.covered(i) ? 1 : 0) != coverage_[i]) return false;
  return true;
}

ConeResult ConeContext::render(const GBuffer& gb, float r_max, const ConeParams& params, std::uint32_t seed, const ProgressFn& progress) {
  const ConeParams p = checked_resolved(params, r_max);
  const VoxelizeOptions options = p.voxelize_options(r_max);
  ConeResult r;
  const auto t0 = std::chrono::steady_clock::now();
  r.grid_reused = grid_is_current(gb, p.grid, options);
  if (!r.grid_reused) {
    valid_ = false;  // until the new grid is complete (a build that throws leaves none)
    grid_ = voxelize(scene_, closure_, gb, p, r_max, &stats_);
    options_ = options;
    if (p.grid == GridSpace::Eye) {
      camera_ = gb.camera;
      depth_.resize(gb.object_id.size());
      coverage_.resize(gb.object_id.size());
      for (std::size_t i = 0; i < depth_.size(); ++i) depth_[i] = gb.depth(i), coverage_[i] = gb.covered(i) ? 1 : 0;
    }
    valid_ = true;
    ++builds_;
    r.voxelize_ms = ms_between(t0, std::chrono::steady_clock::now());
  }
  r.voxel_stats = stats_;
  trace_and_filter(gb, grid_, r_max, p, seed, progress, r);
  return r;
}

nlohmann::json cone_stats(const ConeResult& r) {
  const VoxelStats& v = r.voxel_stats;
  nlohmann::json warnings = nlohmann::json::array();
  if (v.odd_columns > 0)
    warnings.push_back("cone: " + std::to_string(v.odd_columns) +
                       " voxel columns end with odd parity: the scene is not watertight there, voxels behind the leak are wrong");
  if (v.open_meshes > 0)
    warnings.push_back("cone: " + std::to_string(v.open_meshes) + " open surface(s) (" + std::to_string(v.boundary_edges) +
                       " boundary edges in all meshes): filled as one-sided slabs behind their front faces");
  if (v.holed_meshes > 0)
    warnings.push_back("cone: " + std::to_string(v.holed_meshes) + " mesh(es) not closed (" + std::to_string(v.holes) + " hole(s)): " +
                       (v.capped_meshes > 0 ? "solid taken where the generalized winding number exceeds 1/2 (holes closed by fans)"
                                            : "voxelized by parity, wrong in the columns through the holes"));
  return {{"grid_columns", {r.grid_nx, r.grid_ny}},
          {"triangles_rasterised", v.triangles},
          {"fragments", v.fragments},
          {"odd_columns", v.odd_columns},
          {"open_meshes", v.open_meshes},
          {"boundary_edges", v.boundary_edges},
          {"holed_meshes", v.holed_meshes},
          {"holes", v.holes},
          {"set_voxels", v.set_voxels},
          {"voxelize_ms", r.voxelize_ms},
          {"trace_ms", r.trace_ms},
          {"filter_ms", r.filter_ms},
          {"grid_reused", r.grid_reused},
          {"warnings", warnings}};
}

}  // namespace ao
