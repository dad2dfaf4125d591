// Voxel cone traced AO on the world grid (Dalla Favera & Celes 2012, sec. III-C): the kernel's
// per-pixel work, SIMD where the CPU has AVX-512. See cone.h for the convention (V = 1 - the
// paper's blocked fraction), docs/methods/cone.md (Speed) for how it is laid out.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include "ao/core/parallel.h"
#include "ao/methods/cone_kernel_internal.h"

namespace ao::cone_internal {

namespace {

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
  // The grid's constants in vectors, made once per call of the kernel (not rebuilt per sphere).
  struct VecConst {
    __m256 fnx, fny, fbits;
    __m256i last_bit, nx, words, last_byte;  // last_byte: the last 8-byte load that stays in the column
    __m512i one, two;
  };
  VecConst vk{_mm256_set1_ps(static_cast<float>(g.nx)), _mm256_set1_ps(static_cast<float>(g.ny)), _mm256_set1_ps(static_cast<float>(g.depth_bits)),
              _mm256_set1_epi32(g.depth_bits - 1), _mm256_set1_epi32(g.nx), _mm256_set1_epi32(g.words), _mm256_set1_epi32(8 * g.words - 8),
              _mm512_set1_epi64(1), _mm512_set1_epi64(2)};
  // The solid length of the np prisms summed in prism order, 8 at a time: column indices, z ranges,
  // one gathered 64-bit load per prism starting at the byte that holds its first voxel (bits
  // k0 .. k1 of the column are then bits sh .. sh + k1 - k0 of the load, sh = k0 mod 8, or
  // further in at the column's last 8 bytes), masks and VPOPCNTQ. Prisms longer than the load
  // (k1 - k0 + sh > 63) go the scalar way.
  float prisms(float gx, float gy, float gz, float rx, float ry, const float* h, float scale, const float* pu, const float* pv) const {
    const __m256 vscale = _mm256_set1_ps(scale);
    const __m256 zero = _mm256_setzero_ps(), fnx = vk.fnx, fny = vk.fny, fbits = vk.fbits;
    const __m256i last_bit = vk.last_bit, nx = vk.nx, words = vk.words, last_byte = vk.last_byte;
    const __m512i one = vk.one, two = vk.two;
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
      const __m512i x = _mm512_srlv_epi64(word, _mm512_cvtepi32_epi64(sh));  // bit 0 = voxel k0, bit n = voxel k1
      const __m512i top = _mm512_sllv_epi64(one, _mm512_cvtepi32_epi64(n));
      const __mmask8 b0 = _mm512_test_epi64_mask(x, one), b1 = _mm512_test_epi64_mask(x, top);
      // Voxels strictly between the end voxels: bits 1 .. n - 1 of x (n >= 1; n = 0 takes `single`).
      const __m256 fmid = _mm512_cvtepi64_ps(_mm512_popcnt_epi64(_mm512_and_si512(x, _mm512_sub_epi64(top, two))));
      const __m256 fk0 = _mm256_cvtepi32_ps(k0), fk1 = _mm256_cvtepi32_ps(k1);
      // k0 == k1: bit(k0) * (zhi - zlo); else bit(k0) (k0 + 1 - zlo) + between + bit(k1) (zhi - k1).
      const __m256 multi = _mm256_add_ps(_mm256_add_ps(_mm256_maskz_sub_ps(b0, _mm256_add_ps(fk0, _mm256_set1_ps(1.0f)), zlo), fmid),
                                         _mm256_maskz_sub_ps(b1, zhi, fk1));
      const __m256 single = _mm256_maskz_sub_ps(b0, zhi, zlo);
      const __mmask8 one_voxel = _mm256_cmp_epi32_mask(k0, k1, _MM_CMPINT_GE);
      __m256 len = _mm256_maskz_mov_ps(ok, _mm256_mask_blend_ps(one_voxel, multi, single));
      if (wide) {
        alignas(32) float w[8];
        _mm256_store_ps(w, len);
        for (unsigned m = wide; m; m &= m - 1) {
          const int s = s0 + std::countr_zero(m);
          w[s - s0] = scalar_prism(gx, gy, gz, rx, ry, h[s] * scale, pu[s], pv[s]);
        }
        len = _mm256_load_ps(w);
      }
      // Summed lane by lane in prism order, the order of the scalar path, in registers. Lanes past
      // np hold +0, and adding +0 to a sum >= +0 leaves it as it is, so all 8 lanes are added.
      const __m128 a = _mm256_castps256_ps128(len), b = _mm256_extractf128_ps(len, 1);
      __m128 t = _mm_set_ss(solid);
      t = _mm_add_ss(t, a), t = _mm_add_ss(t, _mm_movehdup_ps(a)), t = _mm_add_ss(t, _mm_movehl_ps(a, a)), t = _mm_add_ss(t, _mm_shuffle_ps(a, a, 3));
      t = _mm_add_ss(t, b), t = _mm_add_ss(t, _mm_movehdup_ps(b)), t = _mm_add_ss(t, _mm_movehl_ps(b, b)), t = _mm_add_ss(t, _mm_shuffle_ps(b, b, 3));
      solid = _mm_cvtss_f32(t);
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
      use_a.push_back(real ? q.use_a[j] : 0.0f), use_b.push_back(real ? q.use_b[j] : -1.0f);  // padding: 0 s - 1 < 0
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
  float at_x = 0, at_y = 0, at_z = 0;  // the pixel's point in voxels
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
  // time, each slot taking its cone's scale and axis by a permutation (a gather past 8 cones). The
  // centres and radii are not stored: centre() computes them for the few slots that pass.
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
      const __m512i wm = _mm512_mask_i32gather_epi64(_mm512_setzero_si512(), use, idx, win, 8);
      const __m512i sh = _mm512_cvtepi32_epi64(_mm256_sub_epi32(c63, _mm256_sub_epi32(ch, cl)));
      const __mmask8 any = _mm512_test_epi64_mask(_mm512_srlv_epi64(wm, _mm512_cvtepi32_epi64(cl)), _mm512_srlv_epi64(ones, sh));
      used[i >> 3] = use, wide[i >> 3] = wid, pass[i >> 3] = use & (any | wid);
    }
  }

  // Slot i's centre (voxels) and radius scale as place_flat computes them (the same fused
  // multiply-adds), from the pixel's grid point (gx, gy, gz).
  void centre(const FlatSlots& q, int i, float gx, float gy, float gz, float& px, float& py, float& pz, float& r) const {
    const int c = q.cone[i];
    const float s = scale[c], d = std::fma(q.dist_a[i], s, q.dist_b[i]);
    px = std::fma(ax[c], d, gx), py = std::fma(ay[c], d, gy), pz = std::fma(az[c], d, gz);
    r = std::min(std::fma(q.rad_a[i], s, q.rad_b[i]), 1.0f);
  }
#endif
};

// World grid: per pixel, every sphere is placed and passes the coarse test (PixelSpheres), then
// each cone runs front to back, sampling the prisms of the spheres that passed.
void trace_with(const GBuffer& gb, const WorldSampler& sample, float r_max, const ConeSetup& setup, const ConePattern& pat, ImageView<float> out,
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
  // Front to back along each cone (sec. III-C2, Fig. 8): each sphere absorbs its obstructed
  // fraction f of the rays that reach it, T *= 1 - f, until T <= kOpaque.
  const auto finish = [&](PixelSpheres& ps) {
    const auto fraction = [&](int i, int j) {
      const int k = lanes.k[j];
      const WorldSampler::Sphere& sp = sample.spheres[k];
#if defined(__AVX512F__) && defined(__AVX512VL__) && defined(__AVX512DQ__) && !defined(AO_NO_GATHER)
      float px, py, pz, r;
      ps.centre(flat, i, ps.at_x, ps.at_y, ps.at_z, px, py, pz, r);
#else
      const float px = ps.cx[i], py = ps.cy[i], pz = ps.cz[i], r = ps.rs[i];
#endif
      if (PixelSpheres::bit(ps.wide, i) && !sample.maybe_solid_blocks(px, py, pz, sp.rx * r, sp.ry * r, sp.rz * r)) return 0.0f;
      return sample.fraction(px, py, pz, k, r, ps.u.data(), ps.v.data());
    };
    float v = 0;
    for (int c = 0; c < nc; ++c) {
      float tr = 1.0f;
      const int i0 = c * stride;
      // A sphere that failed the coarse test has f = 0 and leaves T as it is: only the passed
      // ones, in order (bit j: sphere j of the cone).
      for (std::uint32_t m = PixelSpheres::bits(ps.pass, i0, per_cone); m && tr > kOpaque; m &= m - 1) {
        const int j = std::countr_zero(m);
        tr *= 1.0f - fraction(i0 + j, j);
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
        ps.at_x = gx, ps.at_y = gy, ps.at_z = gz;
        ps.place_flat(flat, sample, nc, gx, gy, gz);
#else
        for (int c = 0; c < nc; ++c) ps.place_cone(lanes, sample, c, gx, gy, gz);
#endif
        finish(ps);
      }
    counter.add(static_cast<std::size_t>(t.x1 - t.x0) * (t.y1 - t.y0));
  });
}

}  // namespace

void trace_world(const GBuffer& gb, const VoxelGrid& g, float r_max, const ConeSetup& setup, const ConePattern& pat, ImageView<float> out,
                 const ProgressFn& progress) {
  trace_with(gb, WorldSampler(g, setup, r_max), r_max, setup, pat, out, progress);
}

}  // namespace ao::cone_internal
