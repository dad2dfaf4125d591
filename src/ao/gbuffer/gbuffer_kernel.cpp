// SPDX-License-Identifier: Apache-2.0
// Kernel of the G-buffer pass (gbuffer/render_gbuffer.h; gbuffer_internal.h), compiled once per
// SIMD target: a tile's primary rays in Embree packets (their directions and hits copied in and out
// lane by lane), then each row's points, normals, ids, albedo and UVs assembled in cache from the
// hits and streamed to the images. Embree dispatches its own traversal; what the targets give this
// code is their instruction set for the per-pixel work around it (without them, compiled for
// baseline x86-64, the pass was 5-10% slower than a -march=native build). The file is compiled
// without contraction, so every target gives the same bits.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/gbuffer/gbuffer_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <algorithm>
#include <array>
#include <cstdint>

#include <hwy/highway.h>

#include "ao/core/parallel.h"
#include "ao/reference/packets_internal.h"
#include "ao/gbuffer/gbuffer_kernel_internal.h"
#include "ao/simd/stream_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

namespace {

// A tile (at most kGBufferTileWidth pixels wide) is traced and written in strips one packet block
// high (at most kStripHeight rows): long rows make long streamed runs per channel.
constexpr int kStripHeight = 4;

// What the primary rays of one tile found, per pixel in row-major order within the tile (SoA):
// the tracing phase fills it packet by packet, the shading phase reads it row by row.
struct TileHits {
  static constexpr int kPixels = kGBufferTileWidth * kStripHeight;
  unsigned geom[kPixels], inst[kPixels], prim[kPixels];
  float u[kPixels], v[kPixels];
};

// Traces the primary rays of tile t into `hits`.
template <int N>
void trace_tile(RTCScene bvh, RTCIntersectContext& ctx, const Camera& cam, const RayGenerator& gen, const Tile& t, TileHits& hits) {
  const int tw = t.x1 - t.x0;
  if constexpr (N == 1) {
    for (int y = t.y0; y < t.y1; ++y)
      for (int x = t.x0; x < t.x1; ++x) {
        const Vec3 d = gen(x, y);
        RTCRayHit rh{};
        rh.ray = {cam.eye.x, cam.eye.y, cam.eye.z, 0.0f, d.x, d.y, d.z, 0.0f, kInfinity, 0xffffffffu, 0, 0};
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(bvh, &ctx, &rh);
        const int j = (y - t.y0) * tw + (x - t.x0);
        hits.geom[j] = rh.hit.geomID, hits.inst[j] = rh.hit.instID[0], hits.prim[j] = rh.hit.primID, hits.u[j] = rh.hit.u, hits.v[j] = rh.hit.v;
      }
  } else {
    // Blocks of 4 x (N/4) pixels: square-ish footprints keep the packet's rays coherent. The
    // fields every ray shares (origin at the eye, tnear, mask, ...) are written once per tile;
    // Embree writes only tfar and the hit, so a block refills directions, tfar and geomID.
    constexpr int bw = 4, bh = N / 4;
    alignas(64) typename detail::Packet<N>::RayHit rh;
    alignas(64) std::array<int, N> valid;
    for (int k = 0; k < N; ++k) detail::set_ray_hit(rh, k, cam.eye, {0, 0, 1}, kInfinity);
    for (int by = t.y0; by < t.y1; by += bh)
      for (int bx = t.x0; bx < t.x1; bx += bw) {
        for (int k = 0; k < N; ++k) {
          const int dx = k % bw, dy = k / bw;
          valid[k] = (bx + dx < t.x1 && by + dy < t.y1) ? -1 : 0;
          const Vec3 d = gen(bx + dx, by + dy);
          rh.ray.dir_x[k] = d.x;
          rh.ray.dir_y[k] = d.y;
          rh.ray.dir_z[k] = d.z;
          rh.ray.tfar[k] = kInfinity;
          rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
        }
        detail::Packet<N>::intersect(valid.data(), bvh, &ctx, &rh);
        for (int k = 0; k < N; ++k) {
          if (!valid[k]) continue;
          const int j = (by + k / bw - t.y0) * tw + (bx + k % bw - t.x0);
          hits.geom[j] = rh.hit.geomID[k], hits.inst[j] = rh.hit.instID[0][k], hits.prim[j] = rh.hit.primID[k], hits.u[j] = rh.hit.u[k],
          hits.v[j] = rh.hit.v[k];
        }
      }
  }
}

// One tile row of every G-buffer channel, assembled in cache and then streamed to the images.
struct RowBuffer {
  Vec3 position[kGBufferTileWidth], normal[kGBufferTileWidth], albedo[kGBufferTileWidth];
  std::uint32_t object_id[kGBufferTileWidth], primitive_id[kGBufferTileWidth];
  Vec2 uv[kGBufferTileWidth];

  // Channels a G-buffer rendered without albedo or UVs leaves empty are not written.
  void stream_to(GBuffer& g, int x0, int y, int n) const {
    simd::stream_copy(&g.position(x0, y), position, n * sizeof(Vec3));
    simd::stream_copy(&g.normal(x0, y), normal, n * sizeof(Vec3));
    if (!g.albedo.empty()) simd::stream_copy(&g.albedo(x0, y), albedo, n * sizeof(Vec3));
    simd::stream_copy(&g.object_id(x0, y), object_id, n * sizeof(std::uint32_t));
    simd::stream_copy(&g.primitive_id(x0, y), primitive_id, n * sizeof(std::uint32_t));
    if (!g.uv.empty()) simd::stream_copy(&g.uv(x0, y), uv, n * sizeof(Vec2));
  }
};

// The visible triangle in camera space: what every pixel that sees it interpolates. Consecutive
// pixels mostly see the same triangle, so it is built once per run of such pixels instead of
// once per pixel (the vertex fetches, the cross product and the transforms to camera space).
struct CameraTriangle {
  unsigned geom = RTC_INVALID_GEOMETRY_ID, inst = RTC_INVALID_GEOMETRY_ID, prim = 0;  ///< Embree's ids of the hit.
  std::uint32_t object = 0;    ///< Index into Scene::objects() (object id - 1).
  std::uint32_t triangle = 0;  ///< Triangle within its mesh.
  Vec3 albedo;
  Vec3 q0, q1, q2;  ///< Vertices, camera space (relative to the eye).
  Vec3 ng;          ///< Unit geometric normal, camera space, as wound (not yet turned to the camera).
  Vec3 n0, n1, n2;  ///< Vertex normals, camera space (SurfaceNormal::Shading only).
  Vec2 t0, t1, t2;  ///< Vertex UVs; zero when the mesh has none or UVs are not wanted.

  template <SurfaceNormal kWhich>
  void load(const RayScene& rs, const Camera& cam, const Frame& basis, unsigned g, unsigned i, unsigned p, bool want_uv) {
    geom = g, inst = i, prim = p;
    // An instance's triangle is moved to the world vertex by vertex, so the point, the normal and
    // their rounding are those of the same triangle stored in world space.
    const HitRef hit = resolve(rs, g, i, p);
    const Mesh& m = rs.scene().meshes[hit.mesh];
    object = hit.object, triangle = hit.triangle, albedo = m.albedo;
    const std::uint32_t* tri = &m.indices[3 * static_cast<std::size_t>(hit.triangle)];
    Vec3 p0, p1, p2;
    world_triangle(rs, hit, p0, p1, p2);
    // Moving the vertices to camera space and interpolating there puts each point on the triangle
    // to a few float spacings of the coordinates and the eye, which the ray offsets rely on
    // (reference/ray_offset.h); eye + t * direction would be off by the error of t.
    q0 = basis.to_local(p0 - cam.eye), q1 = basis.to_local(p1 - cam.eye), q2 = basis.to_local(p2 - cam.eye);
    ng = basis.to_local(normalize(cross(p1 - p0, p2 - p0)));
    if constexpr (kWhich == SurfaceNormal::Shading) {
      Vec3 w0 = m.normals[tri[0]], w1 = m.normals[tri[1]], w2 = m.normals[tri[2]];
      if (const Affine3* nt = hit.normal_to_world)  // vertex normals as flatten_instances stores them
        w0 = normalize(nt->vector(w0)), w1 = normalize(nt->vector(w1)), w2 = normalize(nt->vector(w2));
      n0 = basis.to_local(w0), n1 = basis.to_local(w1), n2 = basis.to_local(w2);
    }
    if (want_uv && !m.uvs.empty()) t0 = m.uvs[tri[0]], t1 = m.uvs[tri[1]], t2 = m.uvs[tri[2]];
    else t0 = t1 = t2 = {};
  }
};

// Writes the G-buffer rows of tile t from its hits: each row is assembled in a RowBuffer and
// streamed out, one contiguous run per channel. kExtras: albedo and UVs are wanted (else their
// images are empty and nothing is computed for them).
template <SurfaceNormal kWhich, bool kExtras>
void shade_tile(const RayScene& rs, const Camera& cam, const Frame& basis, const TileHits& hits, GBuffer& g, const Tile& t) {
  const int tw = t.x1 - t.x0;
  const bool want_uv = kExtras && !g.uv.empty();
  RowBuffer row;
  CameraTriangle tri;
  for (int y = t.y0; y < t.y1; ++y) {
    const int r = (y - t.y0) * tw;
    for (int i = 0; i < tw; ++i) {
      const unsigned geom = hits.geom[r + i];
      if (geom == RTC_INVALID_GEOMETRY_ID) {
        row.position[i] = {};
        row.normal[i] = {};
        row.object_id[i] = 0;
        row.primitive_id[i] = 0;
        if constexpr (kExtras) row.albedo[i] = {}, row.uv[i] = {};
        continue;
      }
      const unsigned inst = hits.inst[r + i], prim = hits.prim[r + i];
      if (geom != tri.geom || prim != tri.prim || inst != tri.inst) tri.load<kWhich>(rs, cam, basis, geom, inst, prim, want_uv);
      const float bu = hits.u[r + i], bv = hits.v[r + i], bw = 1.0f - bu - bv;
      const Vec3 pc = tri.q0 * bw + tri.q1 * bu + tri.q2 * bv;
      // Both sides of a surface can be seen (open meshes, rooms): AO is for the side facing the
      // viewer, so turn the geometric normal towards the camera and the shading normal onto its side.
      const Vec3 ng = dot(tri.ng, pc) > 0 ? -tri.ng : tri.ng;
      Vec3 n = ng;
      if constexpr (kWhich == SurfaceNormal::Shading) {
        n = normalize(tri.n0 * bw + tri.n1 * bu + tri.n2 * bv);
        if (dot(n, ng) < 0) n = -n;
        if (!(dot(n, n) > 0.25f)) n = ng;  // zero where the vertex normals cancel
      }
      row.position[i] = pc;
      row.normal[i] = n;
      row.object_id[i] = tri.object + 1;
      row.primitive_id[i] = tri.triangle;
      if constexpr (kExtras) {
        row.albedo[i] = tri.albedo;
        row.uv[i] = {tri.t0.x * bw + tri.t1.x * bu + tri.t2.x * bv, tri.t0.y * bw + tri.t1.y * bu + tri.t2.y * bv};
      }
    }
    row.stream_to(g, t.x0, y, tw);
  }
}

template <int N>
void render_tile(const RayScene& rs, RTCIntersectContext& ctx, const Camera& cam, const Frame& basis, const RayGenerator& gen, SurfaceNormal which,
                 GBuffer& g, const Tile& t) {
  // Strips one packet block high: a strip's streamed stores drain while the next strip's rays
  // traverse the BVH, and its hits stay in the L1 cache between the two phases.
  constexpr int kStrip = N == 1 ? 1 : N / 4;
  static_assert(kStrip <= kStripHeight);
  TileHits hits;
  for (int y = t.y0; y < t.y1; y += kStrip) {
    const Tile s{t.x0, y, t.x1, std::min(y + kStrip, t.y1)};
    trace_tile<N>(ao::embree_scene(rs), ctx, cam, gen, s, hits);
    const bool extras = !g.albedo.empty() || !g.uv.empty();
    if (which == SurfaceNormal::Shading) {
      if (extras) shade_tile<SurfaceNormal::Shading, true>(rs, cam, basis, hits, g, s);
      else shade_tile<SurfaceNormal::Shading, false>(rs, cam, basis, hits, g, s);
    } else {
      if (extras) shade_tile<SurfaceNormal::Geometric, true>(rs, cam, basis, hits, g, s);
      else shade_tile<SurfaceNormal::Geometric, false>(rs, cam, basis, hits, g, s);
    }
  }
  simd::stream_fence();  // the streamed rows are visible to whichever thread reads the G-buffer next
}

}  // namespace

void RenderGBufferTile(const GBufferTileJob& job, int packet_width, RTCIntersectContext& ctx, const Tile& t) {
  detail::dispatch_packet_width(packet_width, [&]<int N>() { render_tile<N>(*job.scene, ctx, *job.camera, job.basis, job.rays, job.normal, *job.g, t); });
}

}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ao::simd {

HWY_EXPORT(RenderGBufferTile);

void render_gbuffer_tile(const GBufferTileJob& job, int packet_width, RTCIntersectContext& ctx, const Tile& t) {
  HWY_DYNAMIC_DISPATCH(RenderGBufferTile)(job, packet_width, ctx, t);
}

}  // namespace ao::simd
#endif
