#include "ao/methods/transfer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "ao/core/error.h"
#include "ao/core/parallel.h"
#include "ao/methods/characteristic.h"
#include "ao/methods/containment.h"
#include "ao/methods/samples.h"
#include "ao/methods/screen_space_internal.h"
#include "ao/methods/transfer_internal.h"

namespace ao {

namespace {
constexpr float kInfinityLike = 1e30f;
// Tiles of 128 x 16 pixels (faster than 64 x 64 in bench transfer/0/2); the generic kernel's
// per-row arrays hold one tile row.
constexpr int kTileWidth = 128, kTileHeight = 16;
constexpr int kMaxRaySteps = 8;
constexpr int kPaletteSize = 32;                  // distinct reflectances a packed palette holds
constexpr std::uint32_t kPaletteMask = 0x1F;      // its index's bits in a packed depth word

// Rec. 709 luminance of W: the method's scalar visibility.
inline float luminance(Vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
}

const ParamTable<TransferParams>& transfer_param_table() {
  using P = Param<TransferParams>;
  static const ParamTable<TransferParams> table{
      "transfer",
      {{P::integer("samples", &TransferParams::samples, Range::closed(1, kMaxScreenSpaceSamples), "", "n in eq. 9: rays per pixel"),
        P::integer("ray_steps", &TransferParams::ray_steps, Range::closed(1, kMaxRaySteps), "", "m: containment tests per ray (sec. 4)"),
        P::boolean("silhouette_elimination", &TransferParams::silhouette_elimination,
                   "AT 4.3: occluded only if the surface in front is less than R in front"),
        P::real("bias", &TransferParams::bias, Range::at_least(0), "world units", "depth-test bias; 0 = auto (as containment)"),
        P::real("albedo_scale", &TransferParams::albedo_scale, Range::closed(0, 1), "", "multiplies a~ and Ld~ (W -> O as it goes to 0)"),
        P::enumeration<TransferReflectance>("reflectance", &TransferParams::reflectance,
                                            {{"albedo", TransferReflectance::Albedo}, {"radiance", TransferReflectance::Radiance}},
                                            "what occluders send back: albedo (eq. 9) or also their direct light (sec. 4.1, needs --sun)")},
       interleave_params(&TransferParams::interleave)}};
  return table;
}

void TransferParams::validate() const { transfer_param_table().validate(*this); }
void to_json(nlohmann::json& j, const TransferParams& p) { j = transfer_param_table().to_json(p); }
void from_json(const nlohmann::json& j, TransferParams& p) { transfer_param_table().from_json(j, p); }

namespace {

#if defined(__AVX512F__)
// An RGB value per blocked lane (a~, or Ld~ in the radiance mode): with a palette, `id` holds
// palette indices and the exact float R, G, B planes of its 32 entries are looked up in registers;
// else `id` holds pixels and the RGB image is read in place, masked (free rays read nothing).
inline void blocked_rgb(bool by_palette, __m512i id, __mmask16 blocked, const float* palette, const float* image, __m512& r, __m512& g,
                        __m512& b) {
  if (by_palette) {
    r = _mm512_permutex2var_ps(_mm512_loadu_ps(palette), id, _mm512_loadu_ps(palette + 16));
    g = _mm512_permutex2var_ps(_mm512_loadu_ps(palette + 32), id, _mm512_loadu_ps(palette + 48));
    b = _mm512_permutex2var_ps(_mm512_loadu_ps(palette + 64), id, _mm512_loadu_ps(palette + 80));
  } else {
    const __m512i a = _mm512_mullo_epi32(id, _mm512_set1_epi32(3));
    r = _mm512_mask_i32gather_ps(_mm512_setzero_ps(), blocked, a, image, 4);
    g = _mm512_mask_i32gather_ps(_mm512_setzero_ps(), blocked, a, image + 1, 4);
    b = _mm512_mask_i32gather_ps(_mm512_setzero_ps(), blocked, a, image + 2, 4);
  }
}
#endif

// The per-row kernel: rays of sample i across the pixels of a row segment in SIMD lanes.
// Sec. 4: I = prod_j I0(x + w r j/m), and a~ comes from the FIRST test point found occluded. The
// tests run from the far end inwards and each occluded one overwrites `at`, so the nearest wins
// without a loop-carried "already hit" test. at = -1: the ray is free; otherwise the pixel whose
// albedo is a~ (the pixel's own when the occluded point is behind the camera, which only an
// analytic characteristic reports: locally homogeneous material). The albedo is then read once per
// blocked ray only (AVX-512: masked gathers, through the exact 32-entry palette when the image has
// one, else in place from the caller's image).
// Each step is its own short loop over the lanes (projection; depth gather; test; accumulation):
// fused, GCC 12 sinks the gathers into branches and the loop no longer if-converts.
// kDirect (radiance mode): the blocked ray also reads the direct radiance Ld~ at the same pixel
// into gain_* (the numerator term of docs/methods/transfer.md's eq. 9'); never with a palette,
// which knows the occluder's albedo but not its pixel.
template <class Characteristic, bool kDirect>
void transfer_row(const Characteristic ch, const ScreenProjection projection, const PixelRow& row, const ContainmentSamples& s, int m,
                  float far_limit, const float* __restrict albedo, const std::uint32_t* __restrict packed, const float* __restrict palette,
                  const float* __restrict direct, int row_base, float* __restrict open, float* __restrict lost_r, float* __restrict lost_g,
                  float* __restrict lost_b, float* __restrict gain_r, float* __restrict gain_g, float* __restrict gain_b) {
  constexpr bool kDepthBuffer = std::is_same_v<Characteristic, DepthBufferCharacteristic>;
  const float inv_m = 1.0f / static_cast<float>(m);
  const int count = row.count;
  const float *__restrict px = row.px.data(), *__restrict py = row.py.data(), *__restrict pz = row.pz.data();
  const float *__restrict tx = row.tx.data(), *__restrict ty = row.ty.data(), *__restrict tz = row.tz.data();
  const float *__restrict bx = row.bx.data(), *__restrict by = row.by.data(), *__restrict bz = row.bz.data();
  const float *__restrict nx = row.nx.data(), *__restrict ny = row.ny.data(), *__restrict nz = row.nz.data();
  const float* __restrict bias = row.bias.data();
  const float* __restrict depth = nullptr;
  if constexpr (kDepthBuffer) depth = ch.depth;
  alignas(64) float wx[kTileWidth], wy[kTileWidth], wz[kTileWidth], dist[kTileWidth];
  alignas(64) int pixel[kTileWidth], at[kTileWidth];
  for (int i = 0; i < s.size(); ++i) {
    const float X = s.x[static_cast<std::size_t>(i)], Y = s.y[static_cast<std::size_t>(i)], Z = s.z[static_cast<std::size_t>(i)];
    for (int k = 0; k < count; ++k) {
      wx[k] = X * tx[k] + Y * bx[k] + Z * nx[k];  // w r of eq. 8
      wy[k] = X * ty[k] + Y * by[k] + Z * ny[k];
      wz[k] = X * tz[k] + Y * bz[k] + Z * nz[k];
      at[k] = -1;
    }
    for (int j = m; j >= 1; --j) {
      const float f = static_cast<float>(j) * inv_m;
      for (int k = 0; k < count; ++k) {
        const float qx = px[k] + f * wx[k], qy = py[k] + f * wy[k], qz = pz[k] + f * wz[k];
        int p;
        const bool in_front = projection.locate(qx, qy, qz, p);  // clamp-to-edge: false only behind the camera
        pixel[k] = in_front ? p : -1;
        if constexpr (kDepthBuffer)
          dist[k] = qz + (in_front ? 0.0f : kInfinity);  // + z* below: ch.distance, sharing the projection
        else
          dist[k] = ch.distance(qx, qy, qz);
      }
      if constexpr (kDepthBuffer)
        for (int k = 0; k < count; ++k) dist[k] += depth[std::max(pixel[k], 0)];
      for (int k = 0; k < count; ++k) {
        const float d = dist[k];
        // AT 4.3; -inf (implicit surfaces: inner along the whole line) is never a distant foreground object.
        const bool near = (d > far_limit) | (d < -kInfinityLike);
        const bool occluded = (d < -bias[k]) & near;
        at[k] = occluded ? (pixel[k] >= 0 ? pixel[k] : row_base + k) : at[k];
      }
    }
    int k0 = 0;
#if defined(__AVX512F__)
    // Masked gathers, 16 lanes: free rays (at < 0) read no albedo at all and keep their sums
    // (the scalar form adds 0 * a, which is the same value for finite a).
    const __m512 one = _mm512_set1_ps(1.0f);
    for (; k0 < count; k0 += 16) {
      const __mmask16 live = static_cast<__mmask16>(count - k0 >= 16 ? 0xFFFF : (1u << (count - k0)) - 1u);
      const __m512i atv = _mm512_maskz_loadu_epi32(live, at + k0);
      const __mmask16 blocked = _mm512_mask_cmpge_epi32_mask(live, atv, _mm512_setzero_si512());
      const __mmask16 free_rays = live & static_cast<__mmask16>(~blocked);
      __m512 ar, ag, ab;
      // With a palette: the index in the low bits of the pixel's packed depth word (make_palette).
      const __m512i id = packed ? _mm512_and_si512(_mm512_mask_i32gather_epi32(_mm512_setzero_si512(), blocked, atv, packed, 4),
                                                   _mm512_set1_epi32(kPaletteMask))
                                : atv;
      blocked_rgb(packed != nullptr, id, blocked, palette, albedo, ar, ag, ab);
      _mm512_mask_storeu_ps(open + k0, free_rays, _mm512_add_ps(_mm512_maskz_loadu_ps(free_rays, open + k0), one));
      _mm512_mask_storeu_ps(lost_r + k0, blocked, _mm512_add_ps(_mm512_maskz_loadu_ps(blocked, lost_r + k0), ar));
      _mm512_mask_storeu_ps(lost_g + k0, blocked, _mm512_add_ps(_mm512_maskz_loadu_ps(blocked, lost_g + k0), ag));
      _mm512_mask_storeu_ps(lost_b + k0, blocked, _mm512_add_ps(_mm512_maskz_loadu_ps(blocked, lost_b + k0), ab));
      if constexpr (kDirect) {
        // (1 - I) Ld~ in the numerator of eq. 9' (docs/methods/transfer.md): Ld at the occluder's pixel.
        __m512 dr, dg, db;
        blocked_rgb(false, atv, blocked, nullptr, direct, dr, dg, db);
        _mm512_mask_storeu_ps(gain_r + k0, blocked, _mm512_add_ps(_mm512_maskz_loadu_ps(blocked, gain_r + k0), dr));
        _mm512_mask_storeu_ps(gain_g + k0, blocked, _mm512_add_ps(_mm512_maskz_loadu_ps(blocked, gain_g + k0), dg));
        _mm512_mask_storeu_ps(gain_b + k0, blocked, _mm512_add_ps(_mm512_maskz_loadu_ps(blocked, gain_b + k0), db));
      }
    }
#endif
    (void)packed, (void)palette, (void)direct, (void)gain_r, (void)gain_g, (void)gain_b;
// Lane k writes only its own accumulators; the gathers read the (read-only) albedo.
#pragma GCC ivdep
    for (int k = k0; k < count; ++k) {
      const float blocked = at[k] >= 0 ? 1.0f : 0.0f;
      const int a = 3 * (at[k] >= 0 ? at[k] : row_base + k);  // always a valid pixel (free: own); int: 32-bit gather indices
      open[k] += 1.0f - blocked;
      // (1 - I) a~ of eq. 9's denominator.
      lost_r[k] += blocked * albedo[a];
      lost_g[k] += blocked * albedo[a + 1];
      lost_b[k] += blocked * albedo[a + 2];
      if constexpr (kDirect) {  // (1 - I) Ld~ in the numerator of eq. 9'
        gain_r[k] += blocked * direct[a];
        gain_g[k] += blocked * direct[a + 1];
        gain_b[k] += blocked * direct[a + 2];
      }
    }
  }
}

#if defined(__AVX512F__)
// The depth-buffer kernel, AVX-512: 16 compacted covered pixels of a row in the lanes of one
// vector, and all n x m tests of them with every per-pixel value and accumulator in registers.
// (The generic transfer_row streams each step through small arrays; here a test is a dozen
// arithmetic instructions and one depth gather, and the tests of successive samples are
// independent, so the core keeps several gathers in flight.) The test point of step j is the
// sample scaled by j/m, p = x + (j/m)(X T + Y B + Z N) (sec. 4), evaluated in the order of
// containment_ao's kernel and with its projection, so with m = 1 both give the same I bit for bit.
// kDirect: the radiance mode (transfer.h), with `packed` null (the occluder's pixel is needed to
// read Ld~ there), three more masked gathers (Ld~ R, G, B) per blocked ray and its own finish;
// the albedo mode (kDirect = false) is compiled exactly as before the mode existed.
// GCC 12 reports the deliberately undefined pass-through operand of unmasked AVX-512 conversions
// (_mm512_cvt_roundps_epi32 and others) as "maybe uninitialized": its intrinsics header
// initialises it from itself.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
template <bool kDirect>
void transfer_row_depth_avx512(const ScreenProjection& projection, const float* __restrict depth, const PixelRow& row,
                               const ContainmentSamples& s, int m, float far_limit, const float* __restrict albedo,
                               const std::uint32_t* __restrict packed, const float* __restrict palette, const float* __restrict direct,
                               const int* index, float n, float albedo_scale, float* __restrict out_r, float* __restrict out_g,
                               float* __restrict out_b, float* __restrict out_o, Vec3* __restrict out_rgb) {
  const __m512 scale_x = _mm512_set1_ps(projection.scale_x), scale_y = _mm512_set1_ps(projection.scale_y);
  const __m512 centre_x = _mm512_set1_ps(projection.centre_x), centre_y = _mm512_set1_ps(projection.centre_y);
  const __m512i row_stride = _mm512_set1_epi32(projection.width);
  const __m512 max_x = _mm512_set1_ps(static_cast<float>(projection.width - 1)), max_y = _mm512_set1_ps(static_cast<float>(projection.height - 1));
  const __m512 zero = _mm512_setzero_ps(), one = _mm512_set1_ps(1.0f), minus_one = _mm512_set1_ps(-1.0f);
  const __m512 far = _mm512_set1_ps(far_limit);
  const __m512i palette_mask = _mm512_set1_epi32(kPaletteMask);
  const __m512 exactness = _mm512_set1_ps(0x1p-16f);
  const float inv_m = 1.0f / static_cast<float>(m);
  // The sample offsets scaled to each step, (j/m)(X, Y, Z), once per row.
  std::array<float, 3 * kMaxScreenSpaceSamples * kMaxRaySteps> offsets;
  for (int i = 0; i < s.size(); ++i)
    for (int j = 1; j <= m; ++j) {
      const float f = static_cast<float>(j) * inv_m;
      float* o = &offsets[3 * (static_cast<std::size_t>(i) * kMaxRaySteps + static_cast<std::size_t>(j - 1))];
      const auto si = static_cast<std::size_t>(i);
      o[0] = f * s.x[si], o[1] = f * s.y[si], o[2] = f * s.z[si];
    }
  for (int k0 = 0; k0 < row.count; k0 += 16) {
    const __mmask16 live = static_cast<__mmask16>(row.count - k0 >= 16 ? 0xFFFF : (1u << (row.count - k0)) - 1u);
    auto load = [&](const std::vector<float>& v) { return _mm512_maskz_loadu_ps(live, v.data() + k0); };
    const __m512 px = load(row.px), py = load(row.py), pz = load(row.pz);
    const __m512 tx = load(row.tx), ty = load(row.ty), tz = load(row.tz);
    const __m512 bx = load(row.bx), by = load(row.by), bz = load(row.bz);
    const __m512 nx = load(row.nx), ny = load(row.ny), nz = load(row.nz);
    const __m512 minus_bias = _mm512_sub_ps(zero, load(row.bias));
    __m512 open_v = zero, lr = zero, lg = zero, lb = zero;
    __m512 gr = zero, gg = zero, gb = zero;  // sum (1 - I) Ld~ (kDirect)
    (void)gr, (void)gg, (void)gb, (void)direct;
    for (int i = 0; i < s.size(); ++i) {
      // Sec. 4: nearest occluded test wins; steps run from the far end inwards, each occluded one
      // overwriting `at`: what identifies a~, the palette index with `packed`, else the pixel.
      __m512i at = _mm512_setzero_si512();
      __mmask16 blocked = 0;
      for (int j = m; j >= 1; --j) {
        const float* o = &offsets[3 * (static_cast<std::size_t>(i) * kMaxRaySteps + static_cast<std::size_t>(j - 1))];
        const __m512 X = _mm512_set1_ps(o[0]), Y = _mm512_set1_ps(o[1]), Z = _mm512_set1_ps(o[2]);
        const __m512 qx = _mm512_fmadd_ps(Z, nx, _mm512_fmadd_ps(Y, bx, _mm512_fmadd_ps(X, tx, px)));
        const __m512 qy = _mm512_fmadd_ps(Z, ny, _mm512_fmadd_ps(Y, by, _mm512_fmadd_ps(X, ty, py)));
        const __m512 qz = _mm512_fmadd_ps(Z, nz, _mm512_fmadd_ps(Y, bz, _mm512_fmadd_ps(X, tz, pz)));
        // ScreenProjection::locate, lane-wise.
        const __m512 inv = _mm512_div_ps(minus_one, qz);
        const __m512 fx = _mm512_fmadd_ps(_mm512_mul_ps(qx, inv), scale_x, centre_x);
        const __m512 fy = _mm512_fnmadd_ps(_mm512_mul_ps(qy, inv), scale_y, centre_y);
        // Clamp-to-edge as ScreenProjection::locate: f clamped to [0, size - 1] as floats before the
        // conversion (max_ps returns its second operand, 0, for a NaN first one); only points behind
        // the camera are free.
        const __m512i ix = _mm512_cvttps_epi32(_mm512_min_ps(_mm512_max_ps(fx, zero), max_x));
        const __m512i iy = _mm512_cvttps_epi32(_mm512_min_ps(_mm512_max_ps(fy, zero), max_y));
        const __mmask16 valid = _mm512_mask_cmp_ps_mask(live, qz, zero, _CMP_LT_OQ);
        const __m512i pixel = _mm512_add_epi32(_mm512_mullo_epi32(iy, row_stride), ix);
        __m512 d;  // z* - depth(p)
        __m512i id = pixel;
        if (packed) {
          // One gather brings z* and the pixel's palette index (make_palette). z* with its low
          // mantissa bits cleared is within 2^-18 of the true depth (relative); only when a
          // comparison below is closer than 2^-16 of the magnitudes involved can it differ, and
          // then the true depth is gathered for those lanes: the tests stay exact.
          const __m512i bits = _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), valid, pixel, packed, 4);
          const __m512 z_near = _mm512_castsi512_ps(_mm512_andnot_si512(palette_mask, bits));
          d = _mm512_add_ps(z_near, qz);
          const __m512 margin = _mm512_mul_ps(_mm512_add_ps(z_near, _mm512_abs_ps(qz)), exactness);
          const __mmask16 close = _mm512_mask_cmp_ps_mask(valid, _mm512_abs_ps(_mm512_sub_ps(d, minus_bias)), margin, _CMP_LT_OQ) |
                                  _mm512_mask_cmp_ps_mask(valid, _mm512_abs_ps(_mm512_sub_ps(d, far)), margin, _CMP_LT_OQ);
          if (close) d = _mm512_mask_add_ps(d, close, _mm512_mask_i32gather_ps(zero, close, pixel, depth, 4), qz);
          id = _mm512_and_si512(bits, palette_mask);
        } else {
          d = _mm512_add_ps(_mm512_mask_i32gather_ps(zero, valid, pixel, depth, 4), qz);
        }
        // AT 4.3: occluded only when the surface in front is less than R in front.
        __mmask16 occluded = _mm512_mask_cmp_ps_mask(valid, d, minus_bias, _CMP_LT_OQ);
        occluded = _mm512_mask_cmp_ps_mask(occluded, d, far, _CMP_GT_OQ);
        at = _mm512_mask_mov_epi32(at, occluded, id);
        blocked |= occluded;
      }
      open_v = _mm512_mask_add_ps(open_v, live & static_cast<__mmask16>(~blocked), open_v, one);
      __m512 ar, ag, ab;
      blocked_rgb(packed != nullptr, at, blocked, palette, albedo, ar, ag, ab);
      // (1 - I) a~ of eq. 9's denominator.
      lr = _mm512_mask_add_ps(lr, blocked, lr, ar);
      lg = _mm512_mask_add_ps(lg, blocked, lg, ag);
      lb = _mm512_mask_add_ps(lb, blocked, lb, ab);
      if constexpr (kDirect) {
        // (1 - I) Ld~ in the numerator of eq. 9', at the same occluder pixel as a~.
        __m512 dr, dg, db;
        blocked_rgb(false, at, blocked, nullptr, direct, dr, dg, db);
        gr = _mm512_mask_add_ps(gr, blocked, gr, dr);
        gg = _mm512_mask_add_ps(gg, blocked, gg, dg);
        gb = _mm512_mask_add_ps(gb, blocked, gb, db);
      }
    }
    // Eq. 9 as in the generic path below, and O = sum I / n (eq. 5), scattered to the entries' pixels.
    const __m512 nv = _mm512_set1_ps(n), scale = _mm512_set1_ps(albedo_scale);
    // Stored, then copied out lane by lane: cheaper than a scatter (microcoded on current cores).
    alignas(64) float wr[16], wg[16], wb[16], o[16];
    if constexpr (kDirect) {
      // (sum I + scale sum (1 - I) Ld~) / (n - scale sum (1 - I) a~), 0 unless both are > 0 (as
      // radiance_ratio below), not clamped: lit occluders can send more than the sky would.
      auto ratio = [&](__m512 lost, __m512 gain) {
        const __m512 num = _mm512_fmadd_ps(scale, gain, open_v), den = _mm512_fnmadd_ps(scale, lost, nv);
        const __mmask16 ok = _mm512_mask_cmp_ps_mask(_mm512_mask_cmp_ps_mask(live, num, zero, _CMP_GT_OQ), den, zero, _CMP_GT_OQ);
        return _mm512_maskz_div_ps(ok, num, den);
      };
      _mm512_store_ps(wr, ratio(lr, gr)), _mm512_store_ps(wg, ratio(lg, gg)), _mm512_store_ps(wb, ratio(lb, gb));
    } else {
      const __mmask16 lit = _mm512_mask_cmp_ps_mask(live, open_v, zero, _CMP_GT_OQ);
      auto ratio = [&](__m512 lost) { return _mm512_maskz_min_ps(lit, _mm512_div_ps(open_v, _mm512_fnmadd_ps(scale, lost, nv)), one); };
      _mm512_store_ps(wr, ratio(lr)), _mm512_store_ps(wg, ratio(lg)), _mm512_store_ps(wb, ratio(lb));
    }
    _mm512_store_ps(o, _mm512_div_ps(open_v, nv));
    for (int k = 0; k < std::min(16, row.count - k0); ++k) {
      const int at_pixel = index[k0 + k];
      if (out_rgb) {  // the final images directly: W interleaved, its luminance in out_r
        const Vec3 c{wr[k], wg[k], wb[k]};
        out_rgb[at_pixel] = c, out_r[at_pixel] = luminance(c), out_o[at_pixel] = o[k];
      } else {
        out_r[at_pixel] = wr[k], out_g[at_pixel] = wg[k], out_b[at_pixel] = wb[k], out_o[at_pixel] = o[k];
      }
    }
  }
}
#pragma GCC diagnostic pop
#endif

#if defined(__AVX512F__)
// An exact palette of the reflectance image: at most 32 distinct RGB triples (bitwise equal),
// whose index per pixel is packed into the low 5 mantissa bits of the pixel's depth. G-buffer
// albedo is per-material constant, so this usually exists. A test's depth gather then also
// brings the index of the albedo a blocked ray reads, and a~ is three in-register table lookups:
// no second gather, no second array in the cache (the gathers' misses are most of the pass's
// time). The depth kernel keeps its tests exact (see transfer_row_depth_avx512). Returns false,
// and the caller reads the image in place, when there are more than 32 values or a depth is
// neither +infinity nor a positive normal float (the packing's bound needs one of those).
bool make_palette(const Image<Vec3>& img, const Image<float>& depth, Image<std::uint32_t>& packed, std::array<float, 96>& planes) {
  const std::size_t n = img.size();
  const Vec3* px = img.data();
  std::array<Vec3, kPaletteSize> entries;
  int used = 0;
  auto find = [&](const Vec3& v) {
    int e = 0;
    while (e < used && std::memcmp(&v, &entries[static_cast<std::size_t>(e)], sizeof(Vec3)) != 0) ++e;
    return e;
  };
  // The distinct values and the depth check, per band in parallel (a band stops at 33 values),
  // then merged in band order, so the palette is the same for any thread count.
  struct Band {
    std::array<Vec3, kPaletteSize + 1> values;
    int count = 0;
    bool depth_ok = true;
  };
  constexpr std::size_t kBand = 1 << 15;
  std::vector<Band> bands((n + kBand - 1) / kBand);
  tbb::parallel_for(std::size_t{0}, bands.size(), [&](std::size_t b) {
    Band& band = bands[b];
    Vec3 last{};
    for (std::size_t i = b * kBand; i < std::min(n, (b + 1) * kBand); ++i) {
      const float z = depth[i];
      band.depth_ok &= z == kInfinity || (z >= std::numeric_limits<float>::min() && z <= std::numeric_limits<float>::max());
      const Vec3 v = px[i];
      if (band.count > 0 && std::memcmp(&v, &last, sizeof(Vec3)) == 0) continue;
      last = v;
      int e = 0;
      while (e < band.count && std::memcmp(&v, &band.values[static_cast<std::size_t>(e)], sizeof(Vec3)) != 0) ++e;
      if (e < band.count) continue;
      if (band.count == kPaletteSize + 1) return;  // too many: the merge fails anyway
      band.values[static_cast<std::size_t>(band.count++)] = v;
    }
  });
  for (const Band& band : bands) {
    if (!band.depth_ok) return false;
    for (int k = 0; k < band.count; ++k) {
      const Vec3 v = band.values[static_cast<std::size_t>(k)];
      if (find(v) < used) continue;
      if (used == kPaletteSize) return false;
      entries[static_cast<std::size_t>(used++)] = v;
    }
  }
  packed.resize(img.width(), img.height());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<std::size_t>& r) {
    int last = -1;
    Vec3 last_v{};
    for (std::size_t i = r.begin(); i < r.end(); ++i) {
      const Vec3 v = px[i];
      if (last < 0 || std::memcmp(&v, &last_v, sizeof(Vec3)) != 0) last = find(v), last_v = v;
      const float z = depth[i];
      std::uint32_t bits;
      std::memcpy(&bits, &z, sizeof bits);
      // +infinity (background) stays exact: it is never an occluder, so it needs no index.
      packed[i] = z == kInfinity ? bits : (bits & ~kPaletteMask) | static_cast<std::uint32_t>(last);
    }
  });
  for (int e = 0; e < used; ++e) {
    const Vec3 v = entries[static_cast<std::size_t>(e)];
    planes[static_cast<std::size_t>(e)] = v.x, planes[static_cast<std::size_t>(32 + e)] = v.y, planes[static_cast<std::size_t>(64 + e)] = v.z;
  }
  return true;
}
#endif

}  // namespace

template <class Characteristic>
const TransferImage& transfer_ao(TransferBuffers& buffers, const GBuffer& g, const Characteristic& ch, const Image<Vec3>& indirect,
                                 const Falloff& falloff, const TransferParams& params, std::uint32_t seed) {
  falloff.validate();
  params.validate();
  const int w = g.width(), h = g.height();
  if (indirect.width() != w || indirect.height() != h) throw InputError("transfer: the indirect reflectance image must have the G-buffer's size");
  const bool radiance = params.reflectance == TransferReflectance::Radiance;
  if (radiance && g.direct.empty())
    throw InputError("transfer: reflectance=radiance reads the occluders' direct light, and the G-buffer has no direct-light pass");
  if (radiance && (g.direct.width() != w || g.direct.height() != h))
    throw InputError("transfer: the G-buffer's direct-light pass must have its size");
  const ContainmentSamples s = make_containment_samples(params.samples, falloff);
  const std::array<Rotation, 16> rotations = interleave_rotations(seed, params.interleave.interleave);
  const float far_limit = params.silhouette_elimination ? -falloff.radius : -kInfinity;  // AT 4.3
  const float n = static_cast<float>(params.samples);
  const float scale = params.albedo_scale;
  const int m = params.ray_steps;
  const bool filter = params.interleave.interleave && params.interleave.filter;
  const ScreenProjection projection = ScreenProjection::from_camera(g.camera);
  // A view of the reflectance: RGB triples, read in place (Vec3 is three packed floats).
  static_assert(sizeof(Vec3) == 3 * sizeof(float));
  const float* albedo = &indirect.data()->x;
  const float* direct = radiance ? &g.direct.data()->x : nullptr;  // Ld~, radiance mode only
#if defined(__AVX512F__)
  alignas(64) std::array<float, 96> palette_rgb{};
  // The radiance mode reads Ld~ at the occluder's pixel, which a palette index does not give.
  // The palette is packed into the G-buffer's depth plane: the characteristic's own when it reads one.
  const std::uint32_t* packed = nullptr;
  if (!radiance) {
    Image<float> own_depth;
    const Image<float>* depth = carried_depth_plane(ch);
    if (!depth) depth = &(own_depth = depth_plane(g));
    if (make_palette(indirect, *depth, buffers.depth_and_palette, palette_rgb)) packed = buffers.depth_and_palette.data();
  }
  const float* palette_rgb_ptr = palette_rgb.data();
#else
  const std::uint32_t* packed = nullptr;
  const float* palette_rgb_ptr = nullptr;
#endif
  TransferImage& out = buffers.result;
  out.transfer.resize(w, h), out.obscurance.resize(w, h), out.luminance.resize(w, h);
  for (Image<float>& p : buffers.scratch) p.resize(w, h);
  // Planar W (R, G, B) and O, the filter's input: its depth tests are then shared by all four.
  // Unfiltered, R goes where the luminance will be and O to its final place.
  float* raw_r = filter ? buffers.scratch[0].data() : out.luminance.data();
  float* raw_g = buffers.scratch[1].data();
  float* raw_b = buffers.scratch[2].data();
  float* raw_o = filter ? buffers.scratch[3].data() : out.obscurance.data();
  // Unfiltered, the AVX-512 depth-buffer kernel writes the final images itself (W interleaved, its
  // luminance where R would go, O), and the interleave pass below is skipped.
#if defined(__AVX512F__)
  const bool kernel_writes_final = !filter && std::is_same_v<Characteristic, DepthBufferCharacteristic>;
#else
  const bool kernel_writes_final = false;
#endif
  Vec3* final_rgb = kernel_writes_final ? out.transfer.data() : nullptr;
  parallel_for_tiles(w, h, kTileWidth, kTileHeight, [&](const Tile& t) {
    // Local copies: their members are then known not to alias the accumulators, so the loop vectorises.
    const Characteristic local_ch = ch;
    const ScreenProjection local_projection = projection;
    PixelRow row;
    std::vector<int> index;  // compacted entry -> offset from t.x0 (AVX-512 depth-buffer path)
    alignas(64) std::array<float, kTileWidth> open, lost_r, lost_g, lost_b, gain_r, gain_g, gain_b;
    for (int y = t.y0; y < t.y1; ++y) {
      const std::size_t base = static_cast<std::size_t>(y) * w + t.x0;
      // Uncovered pixels: W = O = 1. Writing the final images, only those (raw_g, raw_b unused).
      const std::size_t end = base + static_cast<std::size_t>(t.x1 - t.x0);
      if (final_rgb) {
        std::fill(final_rgb + base, final_rgb + end, Vec3{1, 1, 1});
        std::fill(raw_r + base, raw_r + end, luminance(Vec3{1, 1, 1}));
        std::fill(raw_o + base, raw_o + end, 1.0f);
      } else {
        for (float* plane : {raw_r, raw_g, raw_b, raw_o}) std::fill(plane + base, plane + end, 1.0f);
      }
#if defined(__AVX512F__)
      if constexpr (std::is_same_v<Characteristic, DepthBufferCharacteristic>) {
        load_pixel_row_simd(row, index, g, y, t.x0, t.x1, rotations, params.bias, true);
        // The packed words hold the G-buffer's depth plane: used when that is the depth this reads.
        const std::uint32_t* depth_packed = local_ch.depth == ch.plane->data() ? packed : nullptr;
        Vec3* row_rgb = final_rgb ? final_rgb + base : nullptr;
        if (radiance)
          transfer_row_depth_avx512<true>(local_projection, local_ch.depth, row, s, m, far_limit, albedo, nullptr, palette_rgb.data(), direct,
                                          index.data(), n, scale, raw_r + base, raw_g + base, raw_b + base, raw_o + base, row_rgb);
        else
          transfer_row_depth_avx512<false>(local_projection, local_ch.depth, row, s, m, far_limit, albedo, depth_packed, palette_rgb.data(),
                                           nullptr, index.data(), n, scale, raw_r + base, raw_g + base, raw_b + base, raw_o + base,
                                           row_rgb);
        continue;
      }
#endif
      row.load(g, y, t.x0, t.x1, rotations, params.bias);
      open.fill(0.0f), lost_r.fill(0.0f), lost_g.fill(0.0f), lost_b.fill(0.0f);
      if (radiance) {
        gain_r.fill(0.0f), gain_g.fill(0.0f), gain_b.fill(0.0f);
        transfer_row<Characteristic, true>(local_ch, local_projection, row, s, m, far_limit, albedo, nullptr, palette_rgb_ptr, direct,
                                           static_cast<int>(base), open.data(), lost_r.data(), lost_g.data(), lost_b.data(), gain_r.data(),
                                           gain_g.data(), gain_b.data());
      } else {
        transfer_row<Characteristic, false>(local_ch, local_projection, row, s, m, far_limit, albedo, packed, palette_rgb_ptr, nullptr,
                                            static_cast<int>(base), open.data(), lost_r.data(), lost_g.data(), lost_b.data(), nullptr, nullptr,
                                            nullptr);
      }
      for (int k = 0; k < row.count; ++k) {
        const auto ks = static_cast<std::size_t>(k);
        if (!row.covered[ks]) continue;
        const float o = open[ks];
        // Eq. 9. The denominator is >= sum I since a~ <= 1; with no open ray at all W = 0 (0/0 when
        // every ray is blocked by white surfaces: no sky light ever enters).
        auto ratio = [&](float lost) { return o > 0 ? std::min(o / (n - scale * lost), 1.0f) : 0.0f; };
        // The radiance mode (transfer.h): the occluders' direct light joins the numerator. Not
        // clamped (lit occluders can send more light than the sky they hide); 0 when nothing
        // arrives, or when the denominator is 0 (every ray blocked by white surfaces: with light
        // arriving, the bounces of eq. 6 then sum to infinity). With Ld~ = 0 the same value as
        // ratio(): num = o, and o > 0 implies den >= o > 0 for a~ <= 1, where the clamp does nothing.
        auto radiance_ratio = [&](float lost, float gain) {
          const float num = o + scale * gain, den = n - scale * lost;
          return num > 0 && den > 0 ? num / den : 0.0f;
        };
        const std::size_t i = base + ks;
        if (radiance) {
          raw_r[i] = radiance_ratio(lost_r[ks], gain_r[ks]);
          raw_g[i] = radiance_ratio(lost_g[ks], gain_g[ks]);
          raw_b[i] = radiance_ratio(lost_b[ks], gain_b[ks]);
        } else {
          raw_r[i] = ratio(lost_r[ks]);
          raw_g[i] = ratio(lost_g[ks]);
          raw_b[i] = ratio(lost_b[ks]);
        }
        raw_o[i] = o / n;  // eq. 5 from the same tests
      }
    }
  });
  // Sec. 4.2's filter on W and O alike; filtered R goes where the luminance will be.
  float* fr = raw_r;
  float* fg = raw_g;
  float* fb = raw_b;
  if (filter) {
    fr = out.luminance.data(), fg = buffers.scratch[4].data(), fb = buffers.scratch[5].data();
    const std::array<const float*, 4> src{raw_r, raw_g, raw_b, raw_o};
    const std::array<float*, 4> dst{fr, fg, fb, out.obscurance.data()};
    depth_aware_box_filter_planes(src, dst, g, effective_depth_limit(params.interleave, falloff.radius), carried_depth_plane(ch));
  }
  if (kernel_writes_final) return out;  // the kernel wrote the final images
  // Interleave W, and its luminance over the R plane in place (each pixel reads R before writing).
  parallel_for_tiles(w, h, kTileWidth, [&](const Tile& t) {
    for (int y = t.y0; y < t.y1; ++y)
      for (int x = t.x0; x < t.x1; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * w + x;
        const Vec3 c{fr[i], fg[i], fb[i]};
        out.transfer[i] = c;
        out.luminance[i] = luminance(c);
      }
  });
  return out;
}

template <class Characteristic>
TransferImage transfer_ao(const GBuffer& g, const Characteristic& ch, const Image<Vec3>& indirect, const Falloff& falloff,
                          const TransferParams& params, std::uint32_t seed) {
  TransferBuffers buffers;
  transfer_ao(buffers, g, ch, indirect, falloff, params, seed);
  return std::move(buffers.result);
}

TransferImage transfer_ao(const GBuffer& g, const Falloff& falloff, const TransferParams& params, std::uint32_t seed) {
  return transfer_ao(g, DepthBufferCharacteristic(g), g.albedo, falloff, params, seed);
}

const TransferImage& transfer_ao(TransferBuffers& buffers, const GBuffer& g, const Falloff& falloff, const TransferParams& params,
                                 std::uint32_t seed) {
  return transfer_ao(buffers, g, DepthBufferCharacteristic(g), g.albedo, falloff, params, seed);
}

#define AO_INSTANTIATE_TRANSFER(Characteristic)                                                                                       \
  template TransferImage transfer_ao(const GBuffer&, const Characteristic&, const Image<Vec3>&, const Falloff&, const TransferParams&, \
                                     std::uint32_t);                                                                                  \
  template const TransferImage& transfer_ao(TransferBuffers&, const GBuffer&, const Characteristic&, const Image<Vec3>&,             \
                                            const Falloff&, const TransferParams&, std::uint32_t);
AO_INSTANTIATE_TRANSFER(DepthBufferCharacteristic)
AO_INSTANTIATE_TRANSFER(ImplicitCharacteristic)
AO_INSTANTIATE_TRANSFER(HeightFieldCharacteristic)
AO_INSTANTIATE_TRANSFER(DepthTimesHeightField)
AO_INSTANTIATE_TRANSFER(EliminatedDepthTimesHeightField)
#undef AO_INSTANTIATE_TRANSFER

}  // namespace ao
