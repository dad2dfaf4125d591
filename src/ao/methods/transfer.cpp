#include "ao/methods/transfer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include "ao/core/error.h"
#include "ao/core/parallel.h"
#include "ao/methods/characteristic.h"
#include "ao/methods/samples.h"

namespace ao {

namespace {
constexpr float kInfinityLike = 1e30f;
constexpr int kTile = 64;
constexpr int kMaxRaySteps = 8;
}

void TransferParams::validate() const {
  if (samples < 1 || samples > kMaxScreenSpaceSamples)
    throw InputError("transfer: samples must be in [1, " + std::to_string(kMaxScreenSpaceSamples) + "], got " + std::to_string(samples));
  if (ray_steps < 1 || ray_steps > kMaxRaySteps)
    throw InputError("transfer: ray_steps (m) must be in [1, " + std::to_string(kMaxRaySteps) + "], got " + std::to_string(ray_steps));
  if (!(bias >= 0.0f) || !std::isfinite(bias)) throw InputError("transfer: bias must be a finite number >= 0 of world units (0 = auto)");
  if (!(albedo_scale >= 0.0f && albedo_scale <= 1.0f)) throw InputError("transfer: albedo_scale must be in [0, 1]");
  validate_interleave_options(interleave, "transfer");
}

void to_json(nlohmann::json& j, const TransferParams& p) {
  j = {{"samples", p.samples},
       {"ray_steps", p.ray_steps},
       {"silhouette_elimination", p.silhouette_elimination},
       {"bias", p.bias},
       {"albedo_scale", p.albedo_scale}};
  add_interleave_options(j, p.interleave);
}

void from_json(const nlohmann::json& j, TransferParams& p) {
  require_known_keys(j, {"samples", "ray_steps", "silhouette_elimination", "bias", "albedo_scale", "interleave", "filter", "filter_depth_limit"},
                     "transfer");
  try {
    if (j.contains("samples")) p.samples = j.at("samples").get<int>();
    if (j.contains("ray_steps")) p.ray_steps = j.at("ray_steps").get<int>();
    if (j.contains("silhouette_elimination")) p.silhouette_elimination = j.at("silhouette_elimination").get<bool>();
    if (j.contains("bias")) p.bias = j.at("bias").get<float>();
    if (j.contains("albedo_scale")) p.albedo_scale = j.at("albedo_scale").get<float>();
  } catch (const nlohmann::json::exception& e) {
    throw InputError(std::string("transfer: bad parameter type: ") + e.what());
  }
  read_interleave_options(j, p.interleave, "transfer");
}

namespace {

// The per-row kernel: rays of sample i across the pixels of a row segment in SIMD lanes.
// Sec. 4: I = prod_j I0(x + w r j/m), and a~ comes from the FIRST test point found occluded. The
// tests run from the far end inwards and each occluded one overwrites `at`, so the nearest wins
// without a loop-carried "already hit" test. at = -1: the ray is free; otherwise the pixel whose
// albedo is a~ (the pixel's own when the occluded point projects off screen: locally homogeneous
// material). The albedo is then read once per blocked ray only (AVX-512: masked gathers, through
// the exact 32-entry palette when the image has one, else in place from the caller's image).
// Each step is its own short loop over the lanes (projection; depth gather; test; accumulation):
// fused, GCC 12 sinks the gathers into branches and the loop no longer if-converts.
template <class Characteristic>
void transfer_row(const Characteristic ch, const ScreenProjection projection, const PixelRow& row, const ContainmentSamples& s, int m,
                  float far_limit, const float* __restrict albedo, const std::uint8_t* __restrict palette_index, const float* __restrict palette,
                  int row_base, float* __restrict open, float* __restrict lost_r, float* __restrict lost_g, float* __restrict lost_b) {
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
  alignas(64) float wx[kTile], wy[kTile], wz[kTile], dist[kTile];
  alignas(64) int pixel[kTile], at[kTile];
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
        const bool on_screen = projection.locate(qx, qy, qz, p);
        pixel[k] = on_screen ? p : -1;
        if constexpr (kDepthBuffer)
          dist[k] = qz + (on_screen ? 0.0f : kInfinity);  // + z* below: ch.distance, sharing the projection
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
      const __m512 zero = _mm512_setzero_ps();
      __m512 ar, ag, ab;
      if (palette_index) {
        // One byte per pixel (4 bytes read at the pixel's offset; the index array is padded), then
        // the palette's exact float R, G, B planes of 32 entries, looked up in registers.
        const __m512i idx = _mm512_and_si512(_mm512_mask_i32gather_epi32(_mm512_setzero_si512(), blocked, atv, palette_index, 1),
                                             _mm512_set1_epi32(0xFF));
        ar = _mm512_permutex2var_ps(_mm512_loadu_ps(palette), idx, _mm512_loadu_ps(palette + 16));
        ag = _mm512_permutex2var_ps(_mm512_loadu_ps(palette + 32), idx, _mm512_loadu_ps(palette + 48));
        ab = _mm512_permutex2var_ps(_mm512_loadu_ps(palette + 64), idx, _mm512_loadu_ps(palette + 80));
      } else {
        const __m512i a = _mm512_mullo_epi32(atv, _mm512_set1_epi32(3));
        ar = _mm512_mask_i32gather_ps(zero, blocked, a, albedo, 4);
        ag = _mm512_mask_i32gather_ps(zero, blocked, a, albedo + 1, 4);
        ab = _mm512_mask_i32gather_ps(zero, blocked, a, albedo + 2, 4);
      }
      _mm512_mask_storeu_ps(open + k0, free_rays, _mm512_add_ps(_mm512_maskz_loadu_ps(free_rays, open + k0), one));
      _mm512_mask_storeu_ps(lost_r + k0, blocked, _mm512_add_ps(_mm512_maskz_loadu_ps(blocked, lost_r + k0), ar));
      _mm512_mask_storeu_ps(lost_g + k0, blocked, _mm512_add_ps(_mm512_maskz_loadu_ps(blocked, lost_g + k0), ag));
      _mm512_mask_storeu_ps(lost_b + k0, blocked, _mm512_add_ps(_mm512_maskz_loadu_ps(blocked, lost_b + k0), ab));
    }
#endif
    (void)palette_index, (void)palette;
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
    }
  }
}

#if defined(__AVX512F__)
// An exact palette of the reflectance image: one byte per pixel indexing at most 32 distinct RGB
// triples (bitwise equal). G-buffer albedo is per-material constant, so this usually exists; a
// blocked ray's albedo is then one byte gather plus three in-register table lookups instead of
// three float gathers (gather throughput and misses are most of the pass's time). Empty `index`
// when there are more than 32 distinct values: the caller reads the image in place.
struct ReflectancePalette {
  std::vector<std::uint8_t> index;   ///< width * height + 3 (padding for 4-byte gathers).
  alignas(64) std::array<float, 96> planes{};  ///< R[32], G[32], B[32].
};
constexpr int kPaletteSize = 32;

ReflectancePalette make_palette(const Image<Vec3>& img) {
  ReflectancePalette p;
  const std::size_t n = img.size();
  const Vec3* px = img.data();
  p.index.assign(n + 3, 0);
  std::array<Vec3, kPaletteSize> entries;
  int used = 0, last = -1;
  Vec3 last_value{};
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 v = px[i];
    if (last < 0 || std::memcmp(&v, &last_value, sizeof(Vec3)) != 0) {
      int e = 0;
      while (e < used && std::memcmp(&v, &entries[static_cast<std::size_t>(e)], sizeof(Vec3)) != 0) ++e;
      if (e == used) {
        if (used == kPaletteSize) return {};
        entries[static_cast<std::size_t>(used++)] = v;
      }
      last = e, last_value = v;
    }
    p.index[i] = static_cast<std::uint8_t>(last);
  }
  for (int e = 0; e < used; ++e) {
    const Vec3 v = entries[static_cast<std::size_t>(e)];
    p.planes[static_cast<std::size_t>(e)] = v.x, p.planes[static_cast<std::size_t>(32 + e)] = v.y, p.planes[static_cast<std::size_t>(64 + e)] = v.z;
  }
  return p;
}
#endif

}  // namespace

template <class Characteristic>
TransferImage transfer_ao(const GBuffer& g, const Characteristic& ch, const Image<Vec3>& indirect, const Falloff& falloff,
                          const TransferParams& params, std::uint32_t seed) {
  falloff.validate();
  params.validate();
  const int w = g.width(), h = g.height();
  if (indirect.width() != w || indirect.height() != h) throw InputError("transfer: the indirect reflectance image must have the G-buffer's size");
  const ContainmentSamples s = make_containment_samples(params.samples, falloff);
  const std::array<Rotation, 16> rotations = interleave_rotations(seed, params.interleave.interleave);
  const float far_limit = params.silhouette_elimination ? -falloff.radius : -kInfinity;  // AT 4.3
  const float n = static_cast<float>(params.samples);
  const float scale = params.albedo_scale;
  const int m = params.ray_steps;
  const ScreenProjection projection = ScreenProjection::from_camera(g.camera);
  // A view of the reflectance: RGB triples, read in place (Vec3 is three packed floats).
  static_assert(sizeof(Vec3) == 3 * sizeof(float));
  const float* albedo = &indirect.data()->x;
#if defined(__AVX512F__)
  const ReflectancePalette palette = make_palette(indirect);
  const std::uint8_t* palette_index = palette.index.empty() ? nullptr : palette.index.data();
  const float* palette_rgb = palette.planes.data();
#else
  const std::uint8_t* palette_index = nullptr;
  const float* palette_rgb = nullptr;
#endif
  // Planar results (W per channel, O): the filter then shares its depth tests across all four.
  Image<float> wr(w, h, 1.0f), wg(w, h, 1.0f), wb(w, h, 1.0f), obscurance(w, h, 1.0f);
  parallel_for_tiles(w, h, kTile, [&](const Tile& t) {
    // Local copies: their members are then known not to alias the accumulators, so the loop vectorises.
    const Characteristic local_ch = ch;
    const ScreenProjection local_projection = projection;
    PixelRow row;
    alignas(64) std::array<float, kTile> open, lost_r, lost_g, lost_b;
    for (int y = t.y0; y < t.y1; ++y) {
      row.load(g, y, t.x0, t.x1, rotations, params.bias);
      const int count = row.count;
      open.fill(0.0f), lost_r.fill(0.0f), lost_g.fill(0.0f), lost_b.fill(0.0f);
      const std::size_t base = static_cast<std::size_t>(y) * w + t.x0;
      transfer_row(local_ch, local_projection, row, s, m, far_limit, albedo, palette_index, palette_rgb, static_cast<int>(base), open.data(),
                   lost_r.data(), lost_g.data(), lost_b.data());
      for (int k = 0; k < count; ++k) {
        if (!row.covered[static_cast<std::size_t>(k)]) continue;
        const float o = open[static_cast<std::size_t>(k)];
        // Eq. 9. The denominator is >= sum I since a~ <= 1; with no open ray at all W = 0 (0/0 when
        // every ray is blocked by white surfaces: no sky light ever enters).
        auto ratio = [&](float lost) { return o > 0 ? std::min(o / (n - scale * lost), 1.0f) : 0.0f; };
        const std::size_t i = base + static_cast<std::size_t>(k);
        wr[i] = ratio(lost_r[static_cast<std::size_t>(k)]);
        wg[i] = ratio(lost_g[static_cast<std::size_t>(k)]);
        wb[i] = ratio(lost_b[static_cast<std::size_t>(k)]);
        obscurance[i] = o / n;  // eq. 5 from the same tests
      }
    }
  });
  if (params.interleave.interleave && params.interleave.filter) {
    Image<float>* planes[] = {&wr, &wg, &wb, &obscurance};
    depth_aware_box_filter_planes(planes, g, effective_depth_limit(params.interleave, falloff.radius));
  }
  // Interleave in parallel (it was a serial pass on the calling thread); the luminance overwrites
  // the R plane in place (each pixel reads its R before writing), saving an allocation.
  TransferImage out{Image<Vec3>(w, h), std::move(obscurance), std::move(wr)};
  parallel_for_tiles(w, h, kTile, [&](const Tile& t) {
    for (int y = t.y0; y < t.y1; ++y)
      for (int x = t.x0; x < t.x1; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * w + x;
        const float r = out.luminance[i];
        out.transfer[i] = Vec3{r, wg[i], wb[i]};
        out.luminance[i] = 0.2126f * r + 0.7152f * wg[i] + 0.0722f * wb[i];
      }
  });
  return out;
}

TransferImage transfer_ao(const GBuffer& g, const Falloff& falloff, const TransferParams& params, std::uint32_t seed) {
  return transfer_ao(g, DepthBufferCharacteristic(g), g.albedo, falloff, params, seed);
}

template TransferImage transfer_ao(const GBuffer&, const DepthBufferCharacteristic&, const Image<Vec3>&, const Falloff&, const TransferParams&,
                                   std::uint32_t);
template TransferImage transfer_ao(const GBuffer&, const ImplicitCharacteristic&, const Image<Vec3>&, const Falloff&, const TransferParams&,
                                   std::uint32_t);
template TransferImage transfer_ao(const GBuffer&, const HeightFieldCharacteristic&, const Image<Vec3>&, const Falloff&, const TransferParams&,
                                   std::uint32_t);
template TransferImage transfer_ao(const GBuffer&, const DepthTimesHeightField&, const Image<Vec3>&, const Falloff&, const TransferParams&,
                                   std::uint32_t);

}  // namespace ao
