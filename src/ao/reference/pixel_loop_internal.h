// The per-pixel loop the ray-traced references share (tangent_sphere.cpp, transfer_reference.cpp):
// every covered pixel of a G-buffer, in parallel tiles, with the ray setup of
// gbuffer_rays_internal.h (the one raytraced.cpp uses), an Embree intersect context per task, and
// the packet width chosen once for the scene.
// Internal to src/ao/reference/.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "ao/core/gbuffer.h"
#include "ao/core/parallel.h"
#include "ao/core/progress.h"
#include "ao/reference/packets_internal.h"
#include "ao/reference/embree_scene_internal.h"
#include "ao/reference/gbuffer_rays_internal.h"
#include "ao/reference/ray_scene.h"
#include "ao/reference/raytraced.h"

namespace ao::detail {

/// Running sums of one point's samples of a value in [0, 1]; doubles so that a million samples
/// stay exact enough.
struct MeanAccumulator {
  double sum = 0, sum_sq = 0;
  int n = 0;

  void add(double v) {
    sum += v;
    sum_sq += v * v;
    ++n;
  }
  double mean() const { return n > 0 ? sum / n : 1.0; }
  /// Standard error of the mean from the unbiased sample variance (conservative for scrambled
  /// Sobol samples, whose error is usually smaller).
  double std_error() const {
    if (n < 2) return 0.0;
    const double var = std::max(0.0, (sum_sq - sum * sum / n) / (n - 1));
    return std::sqrt(var / n);
  }
};

/// Calls fn.template operator()<N>(ctx, x, y, s) for every covered pixel (x, y) of `g`, with s
/// its PixelSurface (gbuffer_rays_internal.h: world position, unit normal, the geometric normal
/// and scale-free offset rays start along, or `fixed_offset` when > 0), N the scene's packet
/// width; in parallel over 16x16 tiles, reporting progress per tile.
template <class Fn>
void for_each_covered_pixel(const RayScene& rs, const GBuffer& g, float fixed_offset, const ProgressFn& progress, Fn&& fn) {
  constexpr int kTile = 16;
  const int w = g.width(), h = g.height();
  const PixelSurfaceContext surface(g, rs.scene(), rs.bounds(), fixed_offset);
  ProgressCounter counter(progress, static_cast<std::size_t>(w) * h);
  dispatch_packet_width(rs.native_packet_width(), [&]<int N>() {
    parallel_for_tiles(w, h, kTile, [&](const Tile& t) {
      flush_denormals_to_zero();
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      for (int y = t.y0; y < t.y1; ++y)
        for (int x = t.x0; x < t.x1; ++x) {
          if (!g.covered(x, y)) continue;
          fn.template operator()<N>(ctx, x, y, surface(x, y));
        }
      counter.add(static_cast<std::size_t>(t.x1 - t.x0) * (t.y1 - t.y0));
    });
  });
}

/// Traces `count` <= max(N, 16) rays from `origin` in directions dir(i) for i in [0, count), each
/// up to tfar(i), and calls hit(i, distance, object) with `object` the index into
/// Scene::objects() of what was hit (hit_object), or distance = +infinity and object =
/// RTC_INVALID_GEOMETRY_ID where nothing was hit within tfar(i).
template <int N, class Dir, class Far, class Hit>
void trace_closest(const RayScene& rs, RTCIntersectContext& ctx, Vec3 origin, int count, Dir&& dir, Far&& tfar, Hit&& hit) {
  if constexpr (N == 1) {
    for (int i = 0; i < count; ++i) {
      const Vec3 d = dir(i);
      RTCRayHit rh{};
      rh.ray = {origin.x, origin.y, origin.z, 0.0f, d.x, d.y, d.z, 0.0f, tfar(i), 0xffffffffu, 0, 0};
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(embree_scene(rs), &ctx, &rh);
      const bool missed = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID;
      hit(i, missed ? kInfinity : rh.ray.tfar, missed ? RTC_INVALID_GEOMETRY_ID : hit_object(rh.hit.geomID, rh.hit.instID[0]));
    }
  } else {
    for (int first = 0; first < count; first += N) {
      alignas(64) typename Packet<N>::RayHit rh;
      alignas(64) int valid[N];
      const int lanes = std::min(N, count - first);
      for (int k = 0; k < N; ++k) {
        valid[k] = k < lanes ? -1 : 0;
        const int i = first + std::min(k, lanes - 1);
        set_ray_hit(rh, k, origin, dir(i), tfar(i));
      }
      Packet<N>::intersect(valid, embree_scene(rs), &ctx, &rh);
      for (int k = 0; k < lanes; ++k) {
        const bool missed = rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID;
        hit(first + k, missed ? kInfinity : rh.ray.tfar[k], missed ? RTC_INVALID_GEOMETRY_ID : hit_object(rh.hit.geomID[k], rh.hit.instID[0][k]));
      }
    }
  }
}

/// Fills out's mean and largest standard error over covered pixels and its ray count from the
/// per-pixel sample counts.
inline void summarise(RaytracedImage& out, const Image<int>& samples, const GBuffer& g) {
  std::size_t covered = 0;
  double sum_se = 0;
  for (std::size_t i = 0; i < out.std_error.size(); ++i) {
    if (!g.covered(i)) continue;
    ++covered;
    sum_se += out.std_error[i];
    out.max_std_error = std::max(out.max_std_error, static_cast<double>(out.std_error[i]));
    out.rays += static_cast<std::uint64_t>(samples[i]);
  }
  out.mean_std_error = covered > 0 ? sum_se / static_cast<double>(covered) : 0.0;
}

}  // namespace ao::detail
