// SPDX-License-Identifier: Apache-2.0
#include "ao/reference/raytraced.h"

#include <algorithm>
#include <array>
#include <vector>
#include <cmath>
#include <limits>

#include "ao/core/error.h"
#include "ao/core/params_table.h"
#include "ao/core/sampling.h"
#include "ao/reference/gbuffer_rays_internal.h"
#include "ao/reference/pixel_loop_internal.h"
#include "ao/reference/ray_offset.h"
#include "ao/simd/sampling_internal.h"

namespace ao {

namespace {

constexpr int kMaxSamples = 1 << 20;

// The sample set of every point: the first `samples` points of the 2-D Sobol sequence, stored as
// what the direction mapping needs, and randomised per point by a Cranley-Patterson rotation
// (a random shift modulo 1 in each dimension). Each shifted point is uniform on the square, so
// the estimate is unbiased; the shifted set keeps Sobol's low discrepancy (every power-of-two
// prefix of dimension 0 stays one point per stratum); and points with different shifts are
// independent, so the per-pixel standard error is honest. The shift of dimension 1 is a rotation
// about the normal, applied to the tangent frame once per point instead of to every direction.
//
// Directions: u0 -> r^2 (polar map of the square to the unit disk, r = sqrt(u0), phi = 2 pi u1),
// lifted to the hemisphere, z = sqrt(1 - r^2) (Malley's method): cosine-weighted, pdf cos/pi.
struct SampleTable {
  int count = 0;                // samples, rounded up to a whole packet
  std::vector<float> u0;        // Sobol dimension 0 in [0, 1)
  std::vector<float> cos_phi;   // cos(2 pi u1), u1 = Sobol dimension 1
  std::vector<float> sin_phi;   // sin(2 pi u1)
};

std::uint32_t reverse_bits32(std::uint32_t x) {
  x = (x << 16) | (x >> 16);
  x = ((x & 0x00ff00ffu) << 8) | ((x & 0xff00ff00u) >> 8);
  x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
  x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
  x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
  return x;
}

// Sobol dimension 1: direction numbers of the primitive polynomial x + 1, v_{k+1} = v_k ^ (v_k >> 1).
std::uint32_t sobol_dim1(std::uint32_t i) {
  std::uint32_t result = 0;
  for (std::uint32_t v = 1u << 31; i != 0; i >>= 1, v ^= v >> 1)
    if (i & 1u) result ^= v;
  return result;
}

SampleTable make_sample_table(int samples, int packet) {
  SampleTable t;
  t.count = (samples + packet - 1) / packet * packet;
  t.u0.assign(static_cast<std::size_t>(t.count), 0.0f);
  t.cos_phi.assign(static_cast<std::size_t>(t.count), 1.0f);
  t.sin_phi.assign(static_cast<std::size_t>(t.count), 0.0f);
  for (int i = 0; i < samples; ++i) {
    const auto k = static_cast<std::size_t>(i);
    t.u0[k] = to_unit_float(reverse_bits32(static_cast<std::uint32_t>(i)));
    const double phi = 2.0 * 3.14159265358979323846 * to_unit_float(sobol_dim1(static_cast<std::uint32_t>(i)));
    t.cos_phi[k] = static_cast<float>(std::cos(phi));
    t.sin_phi[k] = static_cast<float>(std::sin(phi));
  }
  return t;
}

// One point to estimate: where its rays start and the frame they are drawn in.
struct PointSetup {
  Vec3 origin;        // world space, off the surface
  Vec3 t, b, n;       // tangent frame about the integration normal, rotated by the point's azimuth shift
  Vec3 ng;            // unit geometric normal on the side the rays leave from
  float shift = 0;    // Cranley-Patterson shift of dimension 0, [0, 1)
};

PointSetup setup_point(Vec3 p, Vec3 n, Vec3 ng, float offset, std::uint32_t key) {
  PointSetup s;
  s.origin = p + ng * offset;
  const Frame f = Frame::from_normal(n);
  const float a = 2.0f * kPi * to_unit_float(hash_combine(key, 2u));
  const float ca = std::cos(a), sa = std::sin(a);
  s.t = f.t * ca + f.b * sa;
  s.b = f.b * ca - f.t * sa;
  s.n = n;
  s.ng = ng;
  s.shift = to_unit_float(hash_combine(key, 1u));
  return s;
}

using detail::MeanAccumulator;

// Directions of samples [first, first + N) of point `s` into the packet (the kernel layer's
// cosine_directions), with valid[k] = -1 for the lanes to trace: inside the sample count and above
// the geometric tangent plane. A direction below it (possible about a shading normal) enters the
// surface at once: occluded, mu = 0, counted without a ray.
template <int N>
int fill_directions(const SampleTable& tbl, const PointSetup& s, int first, int end, float* dir_x, float* dir_y, float* dir_z, int* valid) {
  const auto at = static_cast<std::size_t>(first);
  const simd::CosineSamples samples{tbl.u0.data() + at,     tbl.cos_phi.data() + at, tbl.sin_phi.data() + at,
                                    {s.t.x, s.t.y, s.t.z}, {s.b.x, s.b.y, s.b.z},   {s.n.x, s.n.y, s.n.z},
                                    {s.ng.x, s.ng.y, s.ng.z}, s.shift};
  return simd::cosine_directions(samples, N, end - first, dir_x, dir_y, dir_z, valid);
}

// Traces samples [first, end) of one point, at most N, and adds their mu to acc.
template <int N>
void trace_batch(RTCScene bvh, RTCIntersectContext& ctx, const SampleTable& tbl, const PointSetup& s, const Falloff& falloff, int first,
                 int end, typename detail::Packet<N>::RayHit& rh, MeanAccumulator& acc) {
  const float reach = falloff.reach();
  alignas(64) std::array<int, N> valid;
  if constexpr (N == 1) {
    fill_directions<1>(tbl, s, first, end, &rh.ray.dir_x, &rh.ray.dir_y, &rh.ray.dir_z, valid.data());
    rh.ray.tfar = reach;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    float mu = 0.0f;
    if (valid[0]) {
      if (falloff.membership == Membership::Step) {
        rtcOccluded1(bvh, &ctx, &rh.ray);
        mu = rh.ray.tfar < 0 ? 0.0f : 1.0f;
      } else {
        rtcIntersect1(bvh, &ctx, &rh);
        mu = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? 1.0f : falloff.mu(rh.ray.tfar);
      }
    }
    acc.add(1, mu, static_cast<double>(mu) * mu);
  } else {
    const int live = fill_directions<N>(tbl, s, first, end, rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z, valid.data());
    acc.add(std::min(N, end - first), 0.0, 0.0);  // lanes below the surface count as mu = 0
    if (live == 0) return;
    for (int k = 0; k < N; ++k) rh.ray.tfar[k] = reach;
    if (falloff.membership == Membership::Step) {
      // Classical AO needs only "is anything closer than R", the cheaper occlusion query, and
      // mu is 0 or 1, so sum = sum of squares = the number of open rays.
      detail::Packet<N>::occluded(valid.data(), bvh, &ctx, &rh.ray);
      int open = 0;
      for (int k = 0; k < N; ++k) open += (valid[k] != 0) & (rh.ray.tfar[k] >= 0.0f);
      acc.add(0, open, open);
    } else {
      for (int k = 0; k < N; ++k) rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      detail::Packet<N>::intersect(valid.data(), bvh, &ctx, &rh);
      float sum = 0, sum_sq = 0;
      for (int k = 0; k < N; ++k) {
        if (!valid[k]) continue;
        const float mu = rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID ? 1.0f : falloff.mu(rh.ray.tfar[k]);
        sum += mu;
        sum_sq += mu * mu;
      }
      acc.add(0, sum, sum_sq);
    }
  }
}

template <int N>
void init_packet(typename detail::Packet<N>::RayHit& rh) {
  if constexpr (N == 1) {
    rh = {};
    rh.ray.mask = 0xffffffffu;
  } else {
    for (int k = 0; k < N; ++k) detail::set_ray_hit(rh, k, {}, {0, 0, 1}, 0.0f);
  }
}

template <int N>
VisibilityEstimate estimate(RTCScene bvh, RTCIntersectContext& ctx, const SampleTable& tbl, const PointSetup& s, const Falloff& falloff,
                            const RaytracedParams& params, typename detail::Packet<N>::RayHit& rh) {
  if constexpr (N == 1) {
    rh.ray.org_x = s.origin.x;
    rh.ray.org_y = s.origin.y;
    rh.ray.org_z = s.origin.z;
  } else {
    for (int k = 0; k < N; ++k) {
      rh.ray.org_x[k] = s.origin.x;
      rh.ray.org_y[k] = s.origin.y;
      rh.ray.org_z[k] = s.origin.z;
    }
  }
  MeanAccumulator acc;
  const bool adaptive = params.target_error > 0;
  constexpr int batch = N == 1 ? 1 : N;
  for (int first = 0; first < params.samples; first += batch) {
    trace_batch<N>(bvh, ctx, tbl, s, falloff, first, params.samples, rh, acc);
    if (adaptive && acc.n >= params.min_samples && acc.n % 16 == 0 && acc.std_error() <= params.target_error) break;
  }
  return {static_cast<float>(acc.mean()), static_cast<float>(acc.std_error()), acc.n};
}

int table_packet(int native_width) { return std::max(native_width, 1); }

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
  const SampleTable tbl = make_sample_table(params.samples, table_packet(rs.native_packet_width()));
  // No triangle is named: the offset scale is the largest coordinate of the point and the scene.
  const float offset = params.offset > 0 ? params.offset : ray_offset_distance(point_magnitude(p, rs.bounds()));
  const Vec3 nn = normalize(n);
  const PointSetup s = setup_point(p, nn, nn, offset, seed);
  return detail::with_ray_context(rs, [&]<int N>(RTCIntersectContext& ctx) {
    alignas(64) typename detail::Packet<N>::RayHit rh;
    init_packet<N>(rh);
    return estimate<N>(embree_scene(rs), ctx, tbl, s, falloff, params, rh);
  });
}

std::vector<VisibilityEstimate> estimate_visibility_at_points(const RayScene& rs, std::span<const Vec3> points, std::span<const Vec3> normals,
                                                              const Falloff& falloff, const RaytracedParams& params, std::uint32_t seed,
                                                              const ProgressFn& progress) {
  falloff.validate();
  params.validate();
  if (points.size() != normals.size())
    throw InputError("points: " + std::to_string(points.size()) + " points and " + std::to_string(normals.size()) + " normals; give one normal per point");
  if (points.size() > static_cast<std::size_t>(std::numeric_limits<int>::max())) throw InputError("points: more than 2^31 - 1 points");
  std::vector<VisibilityEstimate> out(points.size());
  if (points.empty()) return out;
  const SampleTable tbl = make_sample_table(params.samples, table_packet(rs.native_packet_width()));
  ProgressCounter counter(progress, points.size());
  // The points as one row of "pixels", in tiles of 64.
  detail::for_each_ray_tile(rs, static_cast<int>(points.size()), 1, detail::RayTiling{.tile_width = 64, .tile_height = 1}, counter,
                            [&]<int N>(RTCIntersectContext& ctx, const Tile& t) {
                              alignas(64) typename detail::Packet<N>::RayHit rh;
                              init_packet<N>(rh);
                              for (int i = t.x0; i < t.x1; ++i) {
                                const Vec3 p = points[static_cast<std::size_t>(i)];
                                const Vec3 n = normalize(normals[static_cast<std::size_t>(i)]);
                                const float offset = params.offset > 0 ? params.offset : ray_offset_distance(point_magnitude(p, rs.bounds()));
                                const PointSetup s = setup_point(p, n, n, offset, pixel_seed(seed, i, 0));
                                out[static_cast<std::size_t>(i)] = estimate<N>(embree_scene(rs), ctx, tbl, s, falloff, params, rh);
                              }
                              return static_cast<std::size_t>(t.x1 - t.x0);
                            });
  return out;
}

RaytracedImage render_raytraced(const RayScene& rs, const GBuffer& g, const Falloff& falloff, const RaytracedParams& params,
                                std::uint32_t seed, const ProgressFn& progress) {
  falloff.validate();
  params.validate();
  const int w = g.width(), h = g.height();
  // Every pixel is written by the tiles (uncovered ones: V = 1, no error, no rays), so the images
  // are only sized here and their fresh pages are first touched in parallel.
  RaytracedImage out;
  out.visibility.resize(w, h);
  out.std_error.resize(w, h);
  Image<int> samples;
  samples.resize(w, h);
  const detail::PixelSurfaceContext surface(g, rs.scene(), rs.bounds(), params.offset);
  const SampleTable tbl = make_sample_table(params.samples, table_packet(rs.native_packet_width()));
  const RTCScene bvh = embree_scene(rs);
  ProgressCounter counter(progress, detail::covered_pixel_count(g));
  // Directions spread over the hemisphere: Embree's incoherent hint (RayTiling's default).
  detail::for_each_ray_tile(rs, w, h, detail::RayTiling{}, counter, [&]<int N>(RTCIntersectContext& ctx, const Tile& t) {
    alignas(64) typename detail::Packet<N>::RayHit rh;
    init_packet<N>(rh);
    std::size_t covered = 0;
    for (int y = t.y0; y < t.y1; ++y)
      for (int x = t.x0; x < t.x1; ++x) {
        if (!g.covered(x, y)) {
          out.visibility(x, y) = 1.0f;
          out.std_error(x, y) = 0.0f;
          samples(x, y) = 0;
          continue;
        }
        const detail::PixelSurface ps = surface(x, y);
        const PointSetup s = setup_point(ps.position, ps.normal, ps.geometric, ps.offset, pixel_seed(seed, x, y));
        const VisibilityEstimate e = estimate<N>(bvh, ctx, tbl, s, falloff, params, rh);
        out.visibility(x, y) = e.visibility;
        out.std_error(x, y) = e.std_error;
        samples(x, y) = e.samples;
        ++covered;
      }
    return covered;
  });
  detail::summarise(out, samples, g);
  return out;
}

}  // namespace ao
