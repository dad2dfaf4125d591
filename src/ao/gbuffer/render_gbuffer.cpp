// SPDX-License-Identifier: Apache-2.0
#include "ao/gbuffer/render_gbuffer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "ao/core/error.h"
#include "ao/reference/packets_internal.h"
#include "ao/reference/ray_tiles_internal.h"
#include "ao/gbuffer/gbuffer_kernel_internal.h"

namespace ao {

namespace {

// What the second layer stores for one pixel's ray (GBuffer::second_depth): the hit's depth t
// (the rays are scaled to unit camera-space depth, so t is the linear depth), positive where the
// ray leaves through the triangle (a back face: its outward normal points along the ray) and
// marked where that is a closed solid's exit (solid_exit_sides: a closed mesh seen from outside,
// whichever way its fronts face), negative where it enters one; +infinity without a hit. An open
// mesh's sides are read in the orientation open_mesh_facings gives, not as the file wound them.
struct LayerSides {
  std::vector<std::int8_t> exits;    // solid_exit_sides
  std::vector<std::int8_t> facings;  // open_mesh_facings
};
float second_layer_value(const RayScene& rs, const LayerSides& sides, unsigned geom_id, unsigned inst_id, unsigned prim_id, float u, float v,
                         float t, Vec3 dir) {
  if (geom_id == RTC_INVALID_GEOMETRY_ID) return kInfinity;
  const HitRef hit = resolve(rs, geom_id, inst_id, prim_id, u, v);
  Vec3 p0, p1, p2;
  world_triangle(rs, hit, p0, p1, p2);
  const bool back = dot(cross(p1 - p0, p2 - p0), dir) > 0.0f;
  // Which way the object's fronts face out (+1: as wound, -1: turned over): a closed solid's by its
  // exit side, an open mesh's by its facing; 0 (a flat open mesh, a room) is met from its front.
  const int exit = sides.exits[hit.object], facing = exit != 0 ? exit : sides.facings[hit.object];
  return facing != 0 && back == (facing > 0) ? second_layer_back_face(t, exit != 0) : -t;
}

// Traces tile t's second-layer rays, N to a packet (blocks of 4 x N/4 pixels, as the G-buffer's);
// returns its pixel count (the pass's unit of progress).
// A pixel that traces no ray: the background (nothing behind), or the wall of a room around the eye
// (`rooms`), whose solid is everything outside it (GBuffer::second_depth: solid onward).
template <int N>
std::size_t second_layer_tile(const RayScene& rs, const LayerSides& sides, std::span<const std::uint8_t> rooms,
                              RTCIntersectContext& ctx, const simd::RayGenerator& rays, Vec3 eye, float separation, const GBuffer& g,
                              Image<float>& out, const Tile& t) {
  const auto start = [&](int x, int y) {  // < 0: no ray
    const std::size_t object = g.object_id(x, y) - 1u;  // an id past the scene's objects (another scene's G-buffer) is no room
    return !g.covered(x, y) || (object < rooms.size() && rooms[object] != 0) ? -1.0f : g.depth(x, y) + separation;
  };
  const auto no_ray = [&](int x, int y) { return g.covered(x, y) ? kSecondLayerSolidOnward : kInfinity; };
  if constexpr (N == 1) {
    for (int y = t.y0; y < t.y1; ++y)
      for (int x = t.x0; x < t.x1; ++x) {
        const float t0 = start(x, y);
        out(x, y) = no_ray(x, y);
        if (t0 < 0.0f) continue;
        const Vec3 d = rays(x, y);
        RTCRayHit rh{};
        rh.ray = RTCRay{eye.x, eye.y, eye.z, t0, d.x, d.y, d.z, 0.0f, kInfinity, 0xffffffffu, 0, 0};
        rh.hit.geomID = rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(embree_scene(rs), &ctx, &rh);
        out(x, y) = second_layer_value(rs, sides, rh.hit.geomID, rh.hit.instID[0], rh.hit.primID, rh.hit.u, rh.hit.v, rh.ray.tfar, d);
      }
  } else {
    constexpr int bw = 4, bh = N / 4;
    alignas(64) typename detail::Packet<N>::RayHit rh;
    alignas(64) std::array<int, N> valid;
    for (int by = t.y0; by < t.y1; by += bh)
      for (int bx = t.x0; bx < t.x1; bx += bw) {
        bool any = false;
        for (int k = 0; k < N; ++k) {
          const int x = bx + k % bw, y = by + k / bw;
          const float t0 = x < t.x1 && y < t.y1 ? start(x, y) : -1.0f;
          valid[static_cast<std::size_t>(k)] = t0 >= 0.0f ? -1 : 0;
          detail::set_ray_hit(rh, k, eye, rays(x, y), kInfinity);
          rh.ray.tnear[k] = std::max(t0, 0.0f);
          rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
          any = any || t0 >= 0.0f;
        }
        if (any) detail::Packet<N>::intersect(valid.data(), embree_scene(rs), &ctx, &rh);
        for (int k = 0; k < N; ++k) {
          const int x = bx + k % bw, y = by + k / bw;
          if (x >= t.x1 || y >= t.y1) continue;
          out(x, y) = valid[static_cast<std::size_t>(k)] ? second_layer_value(rs, sides, rh.hit.geomID[k], rh.hit.instID[0][k], rh.hit.primID[k],
                                                                              rh.hit.u[k], rh.hit.v[k], rh.ray.tfar[k], rays(x, y))
                                                         : no_ray(x, y);
        }
      }
  }
  return static_cast<std::size_t>(t.x1 - t.x0) * static_cast<std::size_t>(t.y1 - t.y0);
}

}  // namespace

GBuffer render_gbuffer(const RayScene& rs, const Camera& camera, const GBufferOptions& options, const ProgressFn& progress) {
  GBuffer g;
  render_gbuffer(rs, camera, options, g, progress);
  return g;
}

GBuffer render_gbuffer(const RayScene& rs, const Camera& camera, const ProgressFn& progress) { return render_gbuffer(rs, camera, GBufferOptions{}, progress); }

void render_gbuffer(const RayScene& rs, const Camera& camera, GBuffer& g, const ProgressFn& progress) {
  render_gbuffer(rs, camera, GBufferOptions{}, g, progress);
}

void render_gbuffer(const RayScene& rs, const Camera& camera, const GBufferOptions& options, GBuffer& g, const ProgressFn& progress) {
  camera.validate();
  // Every pixel of every channel is written below, so the channels are only resized: storage of
  // the right size is kept, and fresh pages are first touched by the parallel tiles.
  const int w = camera.width, h = camera.height;
  g.position.resize(w, h);
  g.normal.resize(w, h);
  if (options.albedo) g.albedo.resize(w, h);
  else g.albedo = Image<Vec3>();
  g.object_id.resize(w, h);
  if (options.uv) g.uv.resize(w, h);
  else g.uv = Image<Vec2>();
  g.primitive_id.resize(w, h);
  g.camera = camera;
  g.direct = Image<Vec3>();  // belongs to the lighting of the previous view: render_direct_light makes a new one
  g.second_depth = Image<float>(), g.second_separation = 0;  // belongs to the previous view: render_second_layer
  const Frame basis = camera.basis();
  // Each tile is traced and written by the SIMD kernel (gbuffer_kernel.cpp: simd::render_gbuffer_tile).
  const simd::GBufferTileJob job{&rs, &camera, basis, simd::RayGenerator(camera, basis), options.normal, &g};
  ProgressCounter counter(progress, static_cast<std::size_t>(w) * h);  // a primary ray per pixel
  // Primary rays of neighbouring pixels are coherent; every tile costs about the same, so TBB
  // hands each thread blocks of tiles.
  const detail::RayTiling tiling{simd::kGBufferTileWidth, simd::kGBufferTileHeight, RTC_INTERSECT_CONTEXT_FLAG_COHERENT, true};
  detail::for_each_ray_tile(rs, w, h, tiling, counter, [&]<int N>(RTCIntersectContext& ctx, const Tile& t) {
    simd::render_gbuffer_tile(job, N, ctx, t);
    return static_cast<std::size_t>(t.x1 - t.x0) * static_cast<std::size_t>(t.y1 - t.y0);
  });
}

Image<float> render_second_layer_depth(const RayScene& rs, const GBuffer& g, float separation, const ProgressFn& progress) {
  if (!(std::isfinite(separation) && separation > 0.0f))
    throw InputError("second layer: separation must be finite and > 0 (world units), got " + std::to_string(separation));
  const Camera& camera = g.camera;
  camera.validate();
  const int w = camera.width, h = camera.height;
  Image<float> out(w, h);
  const Frame basis = camera.basis();
  const simd::RayGenerator rays(camera, basis);  // camera-space z of every direction is -1: t is the linear depth
  const std::vector<std::uint8_t> rooms = closed_objects_around(rs.scene(), mesh_sides(rs), camera.eye);
  const LayerSides sides{solid_exit_sides(rs.scene(), mesh_sides(rs), rooms), open_mesh_facings(rs.scene(), mesh_sides(rs))};
  if (g.object_id.width() != w || g.object_id.height() != h) throw InputError("second layer: the G-buffer's images must have its camera's size");
  ProgressCounter counter(progress, static_cast<std::size_t>(w) * h);
  const detail::RayTiling tiling{simd::kGBufferTileWidth, simd::kGBufferTileHeight, RTC_INTERSECT_CONTEXT_FLAG_COHERENT, true};
  detail::for_each_ray_tile(rs, w, h, tiling, counter, [&]<int N>(RTCIntersectContext& ctx, const Tile& t) {
    return second_layer_tile<N>(rs, sides, rooms, ctx, rays, camera.eye, separation, g, out, t);
  });
  return out;
}

void render_second_layer(const RayScene& rs, GBuffer& g, float separation, const ProgressFn& progress) {
  g.second_depth = render_second_layer_depth(rs, g, separation, progress);
  g.second_separation = separation;
}

}  // namespace ao
