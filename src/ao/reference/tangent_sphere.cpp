// SPDX-License-Identifier: Apache-2.0
#include "ao/reference/tangent_sphere.h"

#include <algorithm>
#include <cmath>

#include "ao/core/error.h"
#include "ao/core/sampling.h"
#include "ao/reference/pixel_loop_internal.h"
#include "ao/reference/ray_offset.h"

namespace ao {

namespace {

// Direction about +z with pdf 2 cos^3(theta) / pi from u in [0,1)^2: phi = 2 pi u.x and, since the
// pdf of c = cos(theta) is 4 c^3 on [0, 1], c = (1 - u.y)^(1/4) (inverse of its CDF 1 - c^4, with
// 1 - u.y in (0, 1] so that c > 0 and every ray has a positive length R c).
Vec3 cosine_cubed_hemisphere(Vec2 u) {
  const float c = std::sqrt(std::sqrt(1.0f - u.y));
  const float s = std::sqrt(std::max(0.0f, 1.0f - c * c));
  const float phi = 2.0f * kPi * u.x;
  return {s * std::cos(phi), s * std::sin(phi), c};
}

// One point's estimate about unit normal n, rays from `origin` (the point moved off its surface,
// ray_offset.h): batches of 16 rays (a multiple of every packet width) until `samples`, or with a
// target error until it is met after min_samples.
template <int N>
VisibilityEstimate estimate(const RayScene& rs, RTCIntersectContext& ctx, Vec3 origin, Vec3 n, float radius, const RaytracedParams& params,
                            std::uint32_t seed) {
  const Frame frame = Frame::from_normal(n);
  constexpr int kBatch = 16;
  detail::MeanAccumulator acc;
  Vec3 local[kBatch];
  for (int first = 0; first < params.samples; first += kBatch) {
    const int count = std::min(kBatch, params.samples - first);
    for (int i = 0; i < count; ++i) local[i] = cosine_cubed_hemisphere(sobol_owen_2d(static_cast<std::uint32_t>(first + i), seed));
    detail::trace_closest<N>(
        rs, ctx, origin, count, [&](int i) { return frame.to_world(local[i]); }, [&](int i) { return radius * local[i].z; },
        [&](int i, float d, unsigned) {
          // The chord of S in this direction is R cos(theta) long; its free part ends at D.
          const double f = std::min(1.0, static_cast<double>(d) / (static_cast<double>(radius) * local[i].z));
          acc.add(f * f * f);
        });
    if (params.target_error > 0 && acc.n >= params.min_samples && acc.std_error() <= params.target_error) break;
  }
  return {static_cast<float>(acc.mean()), static_cast<float>(acc.std_error()), acc.n};
}

void check_radius(float radius) {
  if (!(radius > 0.0f) || !std::isfinite(radius))
    throw InputError("tangent-sphere reference: R must be a finite number > 0, got " + std::to_string(radius));
}

}  // namespace

VisibilityEstimate estimate_tangent_sphere(const RayScene& rs, Vec3 p, Vec3 n, float radius, const RaytracedParams& params,
                                           std::uint32_t seed) {
  check_radius(radius);
  params.validate();
  // No triangle is named: the offset scale is the largest coordinate of the point and the scene.
  const float offset = params.offset > 0 ? params.offset : ray_offset_distance(point_magnitude(p, rs.bounds()));
  const Vec3 nn = normalize(n);
  return detail::with_ray_context(rs, [&]<int N>(RTCIntersectContext& ctx) { return estimate<N>(rs, ctx, p + nn * offset, nn, radius, params, seed); });
}

RaytracedImage render_tangent_sphere(const RayScene& rs, const GBuffer& g, float radius, const RaytracedParams& params, std::uint32_t seed,
                                     const ProgressFn& progress) {
  check_radius(radius);
  params.validate();
  const int w = g.width(), h = g.height();
  RaytracedImage out{Image<float>(w, h, 1.0f), Image<float>(w, h, 0.0f)};
  Image<int> samples(w, h, 0);
  detail::for_each_covered_pixel(rs, g, params.offset, progress, [&]<int N>(RTCIntersectContext& ctx, int x, int y, const detail::PixelSurface& s) {
    const Vec3 origin = s.position + s.geometric * s.offset;
    const VisibilityEstimate e = estimate<N>(rs, ctx, origin, s.normal, radius, params, pixel_seed(seed, x, y));
    out.visibility(x, y) = e.visibility;
    out.std_error(x, y) = e.std_error;
    samples(x, y) = e.samples;
  });
  detail::summarise(out, samples, g);
  return out;
}

}  // namespace ao
