#include "ao/methods/transfer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <type_traits>

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
// material). The albedo is then read once per blocked ray, from the caller's image (no copy).
// Each step is its own short loop over the lanes (projection; depth gather; test; accumulation):
// fused, GCC 12 sinks the gathers into branches and the loop no longer if-converts.
template <class Characteristic>
void transfer_row(const Characteristic ch, const ScreenProjection projection, const PixelRow& row, const ContainmentSamples& s, int m,
                  float far_limit, const float* __restrict albedo, int row_base, float* __restrict open, float* __restrict lost_r,
                  float* __restrict lost_g, float* __restrict lost_b) {
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
// Lane k writes only its own accumulators; the gathers read the (read-only) albedo.
#pragma GCC ivdep
    for (int k = 0; k < count; ++k) {
      const float blocked = at[k] >= 0 ? 1.0f : 0.0f;
      const int a = 3 * std::max(at[k], row_base + k);  // always a valid pixel (free: own); int: 32-bit gather indices
      open[k] += 1.0f - blocked;
      // (1 - I) a~ of eq. 9's denominator.
      lost_r[k] += blocked * albedo[a];
      lost_g[k] += blocked * albedo[a + 1];
      lost_b[k] += blocked * albedo[a + 2];
    }
  }
}

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
      transfer_row(local_ch, local_projection, row, s, m, far_limit, albedo, static_cast<int>(base), open.data(), lost_r.data(), lost_g.data(),
                   lost_b.data());
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
  TransferImage out{Image<Vec3>(w, h), std::move(obscurance), Image<float>(w, h)};
  for (std::size_t i = 0; i < out.luminance.size(); ++i) {
    out.transfer[i] = Vec3{wr[i], wg[i], wb[i]};
    out.luminance[i] = 0.2126f * wr[i] + 0.7152f * wg[i] + 0.0722f * wb[i];
  }
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
