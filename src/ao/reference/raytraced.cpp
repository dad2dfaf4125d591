#include "ao/reference/raytraced.h"

#include <array>
#include <cmath>

#include "ao/core/error.h"
#include "ao/core/parallel.h"
#include "ao/core/sampling.h"
#include "ao/reference/packets_internal.h"

namespace ao {

namespace {

constexpr int kTile = 16;
constexpr int kMaxSamples = 1 << 20;

// Running sums for one point; doubles so a million samples of mu in [0,1] stay exact enough.
struct Accumulator {
  double sum = 0, sum_sq = 0;
  int n = 0;

  void add(float mu) {
    sum += mu;
    sum_sq += static_cast<double>(mu) * mu;
    ++n;
  }
  double mean() const { return n > 0 ? sum / n : 1.0; }
  // Standard error of the mean from the unbiased sample variance. With scrambled Sobol samples the
  // true error is usually smaller, so this is a conservative stopping rule and report.
  double std_error() const {
    if (n < 2) return 0.0;
    const double var = std::max(0.0, (sum_sq - sum * sum / n) / (n - 1));
    return std::sqrt(var / n);
  }
};

// Traces samples [first, first + count) of one point's sample set. count <= N.
template <int N>
void trace_batch(const RayScene& rs, RTCIntersectContext& ctx, Vec3 origin, const Frame& frame, const Falloff& falloff, std::uint32_t seed,
                 int first, int count, Accumulator& acc) {
  const float reach = falloff.reach();
  const bool step = falloff.membership == Membership::Step;
  if constexpr (N == 1) {
    for (int i = first; i < first + count; ++i) {
      const Vec3 d = frame.to_world(cosine_hemisphere(sobol_owen_2d(static_cast<std::uint32_t>(i), seed)));
      RTCRayHit rh{};
      rh.ray = {origin.x, origin.y, origin.z, 0.0f, d.x, d.y, d.z, 0.0f, reach, 0xffffffffu, 0, 0};
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      if (step) {
        rtcOccluded1(rs.handle(), &ctx, &rh.ray);
        acc.add(rh.ray.tfar < 0 ? 0.0f : 1.0f);
      } else {
        rtcIntersect1(rs.handle(), &ctx, &rh);
        acc.add(rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? 1.0f : falloff.mu(rh.ray.tfar));
      }
    }
  } else {
    alignas(64) typename detail::Packet<N>::RayHit rh;
    alignas(64) std::array<int, N> valid;
    for (int k = 0; k < N; ++k) {
      valid[k] = k < count ? -1 : 0;
      const Vec3 d = frame.to_world(cosine_hemisphere(sobol_owen_2d(static_cast<std::uint32_t>(first + k), seed)));
      detail::set_ray_hit(rh, k, origin, d, reach);
    }
    if (step) {
      // Classical AO needs only "is anything closer than R", the cheaper occlusion query.
      detail::Packet<N>::occluded(valid.data(), rs.handle(), &ctx, &rh.ray);
      for (int k = 0; k < count; ++k) acc.add(rh.ray.tfar[k] < 0 ? 0.0f : 1.0f);
    } else {
      detail::Packet<N>::intersect(valid.data(), rs.handle(), &ctx, &rh);
      for (int k = 0; k < count; ++k) acc.add(rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID ? 1.0f : falloff.mu(rh.ray.tfar[k]));
    }
  }
}

template <int N>
VisibilityEstimate estimate(const RayScene& rs, RTCIntersectContext& ctx, Vec3 p, Vec3 n, const Falloff& falloff, const RaytracedParams& params,
                            float offset, std::uint32_t seed) {
  const Frame frame = Frame::from_normal(n);
  const Vec3 origin = p + n * offset;
  constexpr int batch = N == 1 ? 16 : N;
  Accumulator acc;
  const bool adaptive = params.target_error > 0;
  for (int first = 0; first < params.samples; first += batch) {
    trace_batch<N>(rs, ctx, origin, frame, falloff, seed, first, std::min(batch, params.samples - first), acc);
    if (adaptive && acc.n >= params.min_samples && acc.std_error() <= params.target_error) break;
  }
  return {static_cast<float>(acc.mean()), static_cast<float>(acc.std_error()), acc.n};
}

}  // namespace

const ParamTable<RaytracedParams>& raytraced_param_table() {
  using P = Param<RaytracedParams>;
  static const ParamTable<RaytracedParams> table{
      "raytraced",
      {P::integer("samples", &RaytracedParams::samples, Range::closed(1, kMaxSamples), "", "rays per pixel; with target_error, the most a pixel may take"),
       P::real("target_error", &RaytracedParams::target_error, Range::closed(0, 0.5), "",
               "stop a pixel once the standard error of its mean is at most this; 0 = off"),
       P::integer("min_samples", &RaytracedParams::min_samples, Range::closed(16, kMaxSamples), "",
                  "with target_error: rays a pixel takes before it may stop (at most samples)"),
       P::real("offset", &RaytracedParams::offset, Range::closed(0, kMaxCoordinate), "world units",
               "ray origin offset along the normal; 0 = RayScene's default; at most kMaxCoordinate (1e9), as scene coordinates")}};
  return table;
}

void RaytracedParams::validate() const {
  raytraced_param_table().validate(*this);
  if (target_error > 0 && min_samples > samples)
    throw InputError("raytraced: min_samples must be at most samples (" + std::to_string(samples) + "), got " + std::to_string(min_samples));
}
void to_json(nlohmann::json& j, const RaytracedParams& p) { j = raytraced_param_table().to_json(p); }
void from_json(const nlohmann::json& j, RaytracedParams& p) { raytraced_param_table().from_json(j, p); }

VisibilityEstimate estimate_visibility(const RayScene& rs, Vec3 p, Vec3 n, const Falloff& falloff, const RaytracedParams& params,
                                       std::uint32_t seed) {
  falloff.validate();
  params.validate();
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  const float offset = params.offset > 0 ? params.offset : rs.self_intersection_offset();
  return detail::dispatch_packet_width(rs.native_packet_width(), [&]<int N>() {
    return estimate<N>(rs, ctx, p, normalize(n), falloff, params, offset, seed);
  });
}

RaytracedImage render_raytraced(const RayScene& rs, const GBuffer& g, const Falloff& falloff, const RaytracedParams& params,
                                std::uint32_t seed, const ProgressFn& progress) {
  falloff.validate();
  params.validate();
  const int w = g.width(), h = g.height();
  RaytracedImage out{Image<float>(w, h, 1.0f), Image<float>(w, h, 0.0f)};
  Image<int> samples(w, h, 0);
  const Frame basis = g.camera.basis();
  const Vec3 eye = g.camera.eye;
  const float offset = params.offset > 0 ? params.offset : rs.self_intersection_offset();
  ProgressCounter counter(progress, static_cast<std::size_t>(w) * h);
  detail::dispatch_packet_width(rs.native_packet_width(), [&]<int N>() {
    parallel_for_tiles(w, h, kTile, [&](const Tile& t) {
      detail::flush_denormals_to_zero();
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      for (int y = t.y0; y < t.y1; ++y)
        for (int x = t.x0; x < t.x1; ++x) {
          if (!g.covered(x, y)) continue;
          const Vec3 p = basis.to_world(g.position(x, y)) + eye;
          const Vec3 n = normalize(basis.to_world(g.normal(x, y)));
          const VisibilityEstimate e = estimate<N>(rs, ctx, p, n, falloff, params, offset, pixel_seed(seed, x, y));
          out.visibility(x, y) = e.visibility;
          out.std_error(x, y) = e.std_error;
          samples(x, y) = e.samples;
        }
      counter.add(static_cast<std::size_t>(t.x1 - t.x0) * (t.y1 - t.y0));
    });
  });
  std::size_t covered = 0;
  double sum_se = 0;
  for (std::size_t i = 0; i < out.std_error.size(); ++i) {
    if (!g.coverage[i]) continue;
    ++covered;
    sum_se += out.std_error[i];
    out.max_std_error = std::max(out.max_std_error, static_cast<double>(out.std_error[i]));
    out.rays += static_cast<std::uint64_t>(samples[i]);
  }
  out.mean_std_error = covered > 0 ? sum_se / static_cast<double>(covered) : 0.0;
  return out;
}

}  // namespace ao
