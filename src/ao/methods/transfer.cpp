#include "ao/methods/transfer.h"

#include <cmath>
#include <string>

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
  const int m = params.ray_steps;
  const ScreenProjection projection = ScreenProjection::from_camera(g.camera);
  // SoA copy of the reflectance so the gathers below read one float each.
  std::vector<float> ar(indirect.size()), ag(indirect.size()), ab(indirect.size());
  for (std::size_t i = 0; i < indirect.size(); ++i) {
    ar[i] = indirect[i].x * params.albedo_scale;
    ag[i] = indirect[i].y * params.albedo_scale;
    ab[i] = indirect[i].z * params.albedo_scale;
  }
  TransferImage out{Image<Vec3>(w, h, Vec3{1, 1, 1}), Image<float>(w, h, 1.0f), Image<float>(w, h, 1.0f)};
  parallel_for_tiles(w, h, kTile, [&](const Tile& t) {
    // A local copy: its members are then known not to alias the accumulators, so the loop vectorises.
    const Characteristic local_ch = ch;
    PixelRow row;
    const auto len = static_cast<std::size_t>(t.x1 - t.x0);
    std::vector<float> open(len), lost_r(len), lost_g(len), lost_b(len), own_r(len), own_g(len), own_b(len);
    for (int y = t.y0; y < t.y1; ++y) {
      row.load(g, y, t.x0, t.x1, rotations, params.bias);
      const int count = row.count;
      std::fill(open.begin(), open.end(), 0.0f);
      std::fill(lost_r.begin(), lost_r.end(), 0.0f);
      std::fill(lost_g.begin(), lost_g.end(), 0.0f);
      std::fill(lost_b.begin(), lost_b.end(), 0.0f);
      const std::size_t base = static_cast<std::size_t>(y) * w + t.x0;
      for (int k = 0; k < count; ++k) {  // a~ where the occluded point projects off screen: the pixel's own (locally homogeneous material)
        own_r[static_cast<std::size_t>(k)] = ar[base + k];
        own_g[static_cast<std::size_t>(k)] = ag[base + k];
        own_b[static_cast<std::size_t>(k)] = ab[base + k];
      }
      float *__restrict o = open.data(), *__restrict lr = lost_r.data(), *__restrict lg = lost_g.data(), *__restrict lb = lost_b.data();
      const float *px = row.px.data(), *py = row.py.data(), *pz = row.pz.data();
      const float *tx = row.tx.data(), *ty = row.ty.data(), *tz = row.tz.data();
      const float *bx = row.bx.data(), *by = row.by.data(), *bz = row.bz.data();
      const float *nx = row.nx.data(), *ny = row.ny.data(), *nz = row.nz.data();
      const float* bias = row.bias.data();
      for (int i = 0; i < s.size(); ++i) {
        const float X = s.x[static_cast<std::size_t>(i)], Y = s.y[static_cast<std::size_t>(i)], Z = s.z[static_cast<std::size_t>(i)];
// Lane k writes only its own accumulator; the gathers read the (read-only) G-buffer.
#pragma GCC ivdep
        for (int k = 0; k < count; ++k) {
          // Sec. 4: I = prod_j I0(x + w r j/m); a~ from the first test point found occluded.
          int hit = -2;  // -2: all free; -1: occluded off screen; else pixel index of the first occluded point
          for (int j = 1; j <= m; ++j) {
            const float f = static_cast<float>(j) / static_cast<float>(m);
            const float qx = px[k] + f * (X * tx[k] + Y * bx[k] + Z * nx[k]);
            const float qy = py[k] + f * (X * ty[k] + Y * by[k] + Z * ny[k]);
            const float qz = pz[k] + f * (X * tz[k] + Y * bz[k] + Z * nz[k]);
            const float d = local_ch.distance(qx, qy, qz);
            // -inf (implicit surfaces: inner along the whole line) is never a distant foreground object.
            const bool near = (d > far_limit) | (d < -kInfinityLike);
            const bool occluded = (d < -bias[k]) & near;
            int at_pixel;
            const bool on_screen = projection.locate(qx, qy, qz, at_pixel);
            hit = (hit == -2 && occluded) ? (on_screen ? at_pixel : -1) : hit;
          }
          const bool free = hit == -2;
          const int at = hit < 0 ? 0 : hit;
          o[k] += free ? 1.0f : 0.0f;
          // (1 - I) a~ of eq. 9's denominator.
          lr[k] += free ? 0.0f : (hit < 0 ? own_r[static_cast<std::size_t>(k)] : ar[static_cast<std::size_t>(at)]);
          lg[k] += free ? 0.0f : (hit < 0 ? own_g[static_cast<std::size_t>(k)] : ag[static_cast<std::size_t>(at)]);
          lb[k] += free ? 0.0f : (hit < 0 ? own_b[static_cast<std::size_t>(k)] : ab[static_cast<std::size_t>(at)]);
        }
      }
      for (int k = 0; k < count; ++k) {
        if (!row.covered[static_cast<std::size_t>(k)]) continue;
        // Eq. 9. The denominator is >= sum I since a~ <= 1; with no open ray at all W = 0 (0/0 when
        // every ray is blocked by white surfaces: no sky light ever enters).
        auto ratio = [&](float lost) { return o[k] > 0 ? std::min(o[k] / (n - lost), 1.0f) : 0.0f; };
        const Vec3 W{ratio(lr[k]), ratio(lg[k]), ratio(lb[k])};
        out.transfer(t.x0 + k, y) = W;
        out.obscurance(t.x0 + k, y) = o[k] / n;  // eq. 5 from the same tests
      }
    }
  });
  if (params.interleave.interleave && params.interleave.filter) {
    const float limit = effective_depth_limit(params.interleave, falloff.radius);
    out.transfer = depth_aware_box_filter(out.transfer, g, limit);
    out.obscurance = depth_aware_box_filter(out.obscurance, g, limit);
  }
  for (std::size_t i = 0; i < out.luminance.size(); ++i) {
    const Vec3 c = out.transfer[i];
    out.luminance[i] = 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
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
