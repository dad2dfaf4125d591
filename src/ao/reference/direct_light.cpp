// SPDX-License-Identifier: Apache-2.0
#include "ao/reference/direct_light.h"

#include <array>
#include <cmath>
#include <string>

#include "ao/core/error.h"
#include "ao/reference/gbuffer_rays_internal.h"
#include "ao/reference/pixel_loop_internal.h"

namespace ao {

namespace {

constexpr int kTile = 32;  // pixels per tile side, as render_gbuffer: a tile is one TBB task

// What one pixel needs from the G-buffer: its shadow ray and the unshadowed Ld.
struct ShadowQuery {
  bool lit = false;  // covered and facing the sun: a ray is traced
  Vec3 origin;       // world space, offset off the surface
  Vec3 radiance;     // a/pi E n.l, before visibility
};

ShadowQuery query(const detail::PixelSurfaceContext& surface, Vec3 light, float e_over_pi, int x, int y) {
  ShadowQuery q;
  const GBuffer& g = surface.g;
  if (!g.covered(x, y)) return q;
  const detail::PixelSurface s = surface(x, y);
  const float cos_theta = dot(s.normal, light);
  if (!(cos_theta > 0.0f)) return q;  // facing away (or grazing): no direct light, no ray
  q.radiance = g.albedo(x, y) * (e_over_pi * cos_theta);  // a/pi * E * max(0, n.l)
  // A sun below the triangle's own plane (possible with a shading normal) is behind the surface:
  // shadowed without a ray, as a ray would enter the surface at once.
  q.lit = dot(s.geometric, light) > 0.0f;
  q.origin = s.position + s.geometric * s.offset;
  return q;
}

// Traces the shadow rays of tile t; returns its covered pixels (the pass's unit of progress).
template <int N>
std::size_t shade_tile(const RayScene& rs, RTCIntersectContext& ctx, const detail::PixelSurfaceContext& surface, Vec3 light, float e_over_pi,
                       Image<Vec3>& out, const Tile& t) {
  if constexpr (N == 1) {
    for (int y = t.y0; y < t.y1; ++y)
      for (int x = t.x0; x < t.x1; ++x) {
        const ShadowQuery q = query(surface, light, e_over_pi, x, y);
        if (!q.lit) continue;
        RTCRay ray{q.origin.x, q.origin.y, q.origin.z, 0.0f, light.x, light.y, light.z, 0.0f, kInfinity, 0xffffffffu, 0, 0};
        rtcOccluded1(embree_scene(rs), &ctx, &ray);
        if (ray.tfar >= 0.0f) out(x, y) = q.radiance;  // Embree sets tfar = -inf on a hit
      }
  } else {
    // Blocks of 4 x (N/4) pixels, as render_gbuffer.
    constexpr int bw = 4, bh = N / 4;
    alignas(64) typename detail::Packet<N>::Ray rays;
    alignas(64) std::array<int, N> valid;
    std::array<Vec3, N> radiance;
    for (int by = t.y0; by < t.y1; by += bh)
      for (int bx = t.x0; bx < t.x1; bx += bw) {
        bool any = false;
        for (int k = 0; k < N; ++k) {
          const int x = bx + k % bw, y = by + k / bw;
          const bool inside = x < t.x1 && y < t.y1;
          const ShadowQuery q = inside ? query(surface, light, e_over_pi, x, y) : ShadowQuery{};
          valid[static_cast<std::size_t>(k)] = q.lit ? -1 : 0;
          radiance[static_cast<std::size_t>(k)] = q.radiance;
          detail::set_ray(rays, k, q.origin, light, kInfinity);
          any = any || q.lit;
        }
        if (!any) continue;
        detail::Packet<N>::occluded(valid.data(), embree_scene(rs), &ctx, &rays);
        for (int k = 0; k < N; ++k)
          if (valid[static_cast<std::size_t>(k)] && rays.tfar[k] >= 0.0f) out(bx + k % bw, by + k / bw) = radiance[static_cast<std::size_t>(k)];
      }
  }
  std::size_t covered = 0;
  for (int y = t.y0; y < t.y1; ++y)
    for (int x = t.x0; x < t.x1; ++x) covered += surface.g.covered(x, y) ? 1 : 0;
  return covered;
}

}  // namespace

void Sun::validate() const {
  if (!is_finite(direction) || std::abs(length(direction) - 1.0f) > 1e-3f)
    throw InputError("sun: direction must be a finite unit vector (towards the sun)");
  if (!(irradiance >= 0.0f) || !std::isfinite(irradiance))
    throw InputError("sun: irradiance E must be a finite number >= 0 (units of the ambient radiance), got " + std::to_string(irradiance));
}

Image<Vec3> render_direct_light(const RayScene& rs, const GBuffer& g, const Sun& sun, const ProgressFn& progress) {
  sun.validate();
  const int w = g.width(), h = g.height();
  if (g.albedo.width() != w || g.albedo.height() != h)
    throw InputError("direct light: the G-buffer has no albedo image (render it with GBufferOptions::albedo = true)");
  Image<Vec3> out(w, h);  // 0: written only where lit and unshadowed
  const Vec3 light = normalize(sun.direction);
  const float e_over_pi = sun.irradiance / kPi;  // the diffuse BRDF a/pi times E
  const detail::PixelSurfaceContext surface(g, rs.scene(), rs.bounds(), 0.0f);
  ProgressCounter counter(progress, detail::covered_pixel_count(g));
  // Parallel rays from neighbouring pixels: as coherent as primary rays.
  const detail::RayTiling tiling{kTile, kTile, RTC_INTERSECT_CONTEXT_FLAG_COHERENT};
  detail::for_each_ray_tile(rs, w, h, tiling, counter, [&]<int N>(RTCIntersectContext& ctx, const Tile& t) {
    return shade_tile<N>(rs, ctx, surface, light, e_over_pi, out, t);
  });
  return out;
}

}  // namespace ao
