// SPDX-License-Identifier: Apache-2.0
#include "ao/reference/transfer_reference.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "ao/core/color_shared.h"
#include "ao/core/error.h"
#include "ao/core/sampling.h"
#include "ao/reference/pixel_loop_internal.h"
#include "ao/reference/ray_offset.h"

namespace ao {

namespace {

constexpr Vec3 kLuminance{shared::kLuminanceR, shared::kLuminanceG, shared::kLuminanceB};  // Rec. 709, as the method's luminance

// Running sums of o_i and, per channel, of the denominators' samples q_i = 1 - l_i, for the ratio
// W = sum o / sum q and its delta-method variance (1/n) var(o - W q) / mean(q)^2.
struct RatioAccumulator {
  double so = 0, soo = 0;
  double sq[3] = {0, 0, 0}, sqq[3] = {0, 0, 0}, soq[3] = {0, 0, 0};
  int n = 0;

  void add(double o, const double q[3]) {
    so += o, soo += o * o;
    for (int c = 0; c < 3; ++c) sq[c] += q[c], sqq[c] += q[c] * q[c], soq[c] += o * q[c];
    ++n;
  }
  double obscurance() const { return n > 0 ? so / n : 1.0; }
  // W = 0 with no open direction (so = 0), and then also when every direction is blocked by a
  // white occluder (0/0). sum q >= sum o since a <= 1, so W <= 1; the clamp only absorbs rounding.
  double transfer(int c) const {
    if (n == 0) return 1.0;
    return so > 0 ? std::min(1.0, so / sq[c]) : 0.0;
  }
  double channel_std_error(int c) const {
    if (n < 2 || so <= 0) return 0.0;
    const double w = transfer(c), mq = sq[c] / n;
    const double ss = std::max(0.0, soo - 2 * w * soq[c] + w * w * sqq[c]);  // sum of (o - W q)^2
    return std::sqrt(ss / (static_cast<double>(n) * (n - 1))) / mq;
  }
  double luminance() const { return kLuminance.x * transfer(0) + kLuminance.y * transfer(1) + kLuminance.z * transfer(2); }
  // The luminance's standard error is at most this weighted sum (the channels are correlated).
  double std_error() const {
    return kLuminance.x * channel_std_error(0) + kLuminance.y * channel_std_error(1) + kLuminance.z * channel_std_error(2);
  }
};

// One point's estimate about unit normal n, rays from `origin` (the point moved off its surface,
// ray_offset.h).
// `albedo_of(object)` is the albedo of the occluder hit.
template <int N, class AlbedoOf>
TransferEstimate estimate(const RayScene& rs, RTCIntersectContext& ctx, Vec3 origin, Vec3 n, const Falloff& falloff,
                          const AlbedoOf& albedo_of, const RaytracedParams& params, std::uint32_t seed) {
  const Frame frame = Frame::from_normal(n);
  const float reach = falloff.reach();
  constexpr int kBatch = 16;
  RatioAccumulator acc;
  for (int first = 0; first < params.samples; first += kBatch) {
    const int count = std::min(kBatch, params.samples - first);
    detail::trace_closest<N>(
        rs, ctx, origin, count,
        [&](int i) { return frame.to_world(cosine_hemisphere(sobol_owen_2d(static_cast<std::uint32_t>(first + i), seed))); },
        [&](int) { return reach; },
        [&](int, float d, unsigned object) {
          // Eq. 4's two integrands over cosine-weighted directions: mu(d) of the sky, and the
          // occluder's albedo weighted by 1 - mu(d); nothing hit within the reach is open sky.
          const double mu = object == RTC_INVALID_GEOMETRY_ID ? 1.0 : falloff.mu(d);
          const Vec3 a = object == RTC_INVALID_GEOMETRY_ID ? Vec3{} : albedo_of(object);
          const double q[3] = {1.0 - (1.0 - mu) * a.x, 1.0 - (1.0 - mu) * a.y, 1.0 - (1.0 - mu) * a.z};
          acc.add(mu, q);
        });
    if (params.target_error > 0 && acc.n >= params.min_samples && acc.std_error() <= params.target_error) break;
  }
  TransferEstimate e;
  e.transfer = {static_cast<float>(acc.transfer(0)), static_cast<float>(acc.transfer(1)), static_cast<float>(acc.transfer(2))};
  e.luminance = static_cast<float>(acc.luminance());
  e.obscurance = static_cast<float>(acc.obscurance());
  e.std_error = static_cast<float>(acc.std_error());
  e.samples = acc.n;
  return e;
}

// Albedo by object (Scene::objects(), the ids trace_closest reports), scaled.
std::vector<Vec3> scaled_albedos(const RayScene& rs, float scale) {
  if (!(scale >= 0.0f && scale <= 1.0f)) throw InputError("transfer reference: albedo scale must be in [0, 1], got " + std::to_string(scale));
  std::vector<Vec3> a;
  for (const SceneObject& o : rs.scene().objects()) a.push_back(rs.scene().meshes[o.mesh].albedo * scale);
  return a;
}

}  // namespace

TransferEstimate estimate_transfer(const RayScene& rs, Vec3 p, Vec3 n, const Falloff& falloff, float albedo_scale, const RaytracedParams& params,
                                   std::uint32_t seed) {
  falloff.validate();
  params.validate();
  const std::vector<Vec3> albedo = scaled_albedos(rs, albedo_scale);
  // No triangle is named: the offset scale is the largest coordinate of the point and the scene.
  const float offset = params.offset > 0 ? params.offset : ray_offset_distance(point_magnitude(p, rs.bounds()));
  const Vec3 nn = normalize(n);
  const auto albedo_of = [&](unsigned object) { return albedo[object]; };
  return detail::with_ray_context(rs, [&]<int N>(RTCIntersectContext& ctx) { return estimate<N>(rs, ctx, p + nn * offset, nn, falloff, albedo_of, params, seed); });
}

TransferReferenceImage render_transfer_reference(const RayScene& rs, const GBuffer& g, const Falloff& falloff, float albedo_scale,
                                                 const RaytracedParams& params, std::uint32_t seed, const ProgressFn& progress, TransferAlbedo source) {
  falloff.validate();
  params.validate();
  const std::vector<Vec3> albedo = scaled_albedos(rs, albedo_scale);
  if (source == TransferAlbedo::Receiver && g.albedo.empty())
    throw InputError("transfer reference with the receiver's albedo: the G-buffer has no albedo");
  const int w = g.width(), h = g.height();
  TransferReferenceImage out{Image<Vec3>(w, h, Vec3{1.0f, 1.0f, 1.0f}), {Image<float>(w, h, 1.0f), Image<float>(w, h, 0.0f)},
                             Image<float>(w, h, 1.0f)};
  Image<int> samples(w, h, 0);
  detail::for_each_covered_pixel(rs, g, params.offset, progress, [&]<int N>(RTCIntersectContext& ctx, int x, int y, const detail::PixelSurface& s) {
    const Vec3 origin = s.position + s.geometric * s.offset;
    const Vec3 receiver = source == TransferAlbedo::Receiver ? g.albedo(x, y) * albedo_scale : Vec3{};
    const auto albedo_of = [&](unsigned object) { return source == TransferAlbedo::Receiver ? receiver : albedo[object]; };
    const TransferEstimate e = estimate<N>(rs, ctx, origin, s.normal, falloff, albedo_of, params, pixel_seed(seed, x, y));
    out.transfer(x, y) = e.transfer;
    out.scalar.visibility(x, y) = e.luminance;
    out.scalar.std_error(x, y) = e.std_error;
    out.obscurance(x, y) = e.obscurance;
    samples(x, y) = e.samples;
  });
  detail::summarise(out.scalar, samples, g);
  return out;
}

}  // namespace ao
