// SPDX-License-Identifier: Apache-2.0
// The per-pixel loop the ray-traced references share (tangent_sphere.cpp, transfer_reference.cpp):
// every covered pixel of a G-buffer, in the tiles of ray_tiles_internal.h, with the ray setup of
// gbuffer_rays_internal.h (the one raytraced.cpp uses).
// Internal to src/ao/reference/.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "ao/core/gbuffer.h"
#include "ao/core/parallel.h"
#include "ao/core/progress.h"
#include "ao/reference/gbuffer_rays_internal.h"
#include "ao/reference/mean_accumulator_internal.h"
#include "ao/reference/ray_tiles_internal.h"
#include "ao/reference/ray_scene.h"
#include "ao/reference/raytraced.h"

namespace ao::detail {

/// The number of covered pixels of `g`: the work of a pass that traces rays from them.
inline std::size_t covered_pixel_count(const GBuffer& g) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < g.object_id.size(); ++i) n += g.covered(i) ? 1 : 0;
  return n;
}

/// Calls fn.template operator()<N>(ctx, x, y, s) for every covered pixel (x, y) of `g`, with s
/// its PixelSurface (gbuffer_rays_internal.h: world position, unit normal, the geometric normal
/// and scale-free offset rays start along, or `fixed_offset` when > 0), N the scene's packet
/// width; in parallel over 16x16 tiles (ray_tiles_internal.h), reporting progress in covered pixels.
template <class Fn>
void for_each_covered_pixel(const RayScene& rs, const GBuffer& g, float fixed_offset, const ProgressFn& progress, Fn&& fn) {
  const PixelSurfaceContext surface(g, rs.scene(), rs.bounds(), fixed_offset);
  ProgressCounter counter(progress, covered_pixel_count(g));
  for_each_ray_tile(rs, g.width(), g.height(), RayTiling{}, counter, [&]<int N>(RTCIntersectContext& ctx, const Tile& t) {
    std::size_t covered = 0;
    for (int y = t.y0; y < t.y1; ++y)
      for (int x = t.x0; x < t.x1; ++x) {
        if (!g.covered(x, y)) continue;
        fn.template operator()<N>(ctx, x, y, surface(x, y));
        ++covered;
      }
    return covered;
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
