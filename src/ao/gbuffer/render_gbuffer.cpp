#include "ao/gbuffer/render_gbuffer.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>

#include <emmintrin.h>

#include "ao/reference/ray_tiles_internal.h"

namespace ao {

namespace {

// A tile is kTileWidth x kTileHeight pixels (TBB hands each thread blocks of tiles), traced and
// written in strips one packet block high (at most kStripHeight rows): long rows make long
// streamed runs per channel.
constexpr int kTileWidth = 64, kTileHeight = 16, kStripHeight = 4;

// World-space direction through pixel centre (x + 0.5, y + 0.5) as origin + x * dx + y * dy: the
// per-pixel work of Camera::camera_direction with the trigonometry done once per image.
struct RayGenerator {
  Vec3 origin, dx, dy;

  RayGenerator(const Camera& cam, const Frame& basis) {
    const Vec3 d00 = basis.to_world(cam.camera_direction(0.5f, 0.5f));
    dx = basis.to_world(cam.camera_direction(1.5f, 0.5f)) - d00;
    dy = basis.to_world(cam.camera_direction(0.5f, 1.5f)) - d00;
    origin = d00;
  }
  Vec3 operator()(int x, int y) const { return origin + dx * static_cast<float>(x) + dy * static_cast<float>(y); }
};

// What the primary rays of one tile found, per pixel in row-major order within the tile (SoA):
// the tracing phase fills it packet by packet, the shading phase reads it row by row.
struct TileHits {
  static constexpr int kPixels = kTileWidth * kStripHeight;
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

// Copies `bytes` bytes from src to dst with non-temporal (streaming) stores where dst is 16-byte
// aligned, plain stores at the unaligned ends. The G-buffer (32-52 bytes a pixel, tens of MB) is
// written once and read later by another pass, so streaming it skips reading every destination
// cache line into the cache before overwriting it: half the memory traffic of plain stores.
// Callers issue _mm_sfence() before other threads may read what was written.
void stream_copy(void* dst, const void* src, std::size_t bytes) {
  auto* d = static_cast<unsigned char*>(dst);
  const auto* s = static_cast<const unsigned char*>(src);
  const std::size_t head = std::min(bytes, (16 - reinterpret_cast<std::uintptr_t>(d) % 16) % 16);
  std::memcpy(d, s, head);
  d += head, s += head, bytes -= head;
  for (; bytes >= 16; d += 16, s += 16, bytes -= 16)
    _mm_stream_si128(reinterpret_cast<__m128i*>(d), _mm_loadu_si128(reinterpret_cast<const __m128i*>(s)));
  std::memcpy(d, s, bytes);
}

// One tile row of every G-buffer channel, assembled in cache and then streamed to the images.
struct RowBuffer {
  Vec3 position[kTileWidth], normal[kTileWidth], albedo[kTileWidth];
  std::uint32_t object_id[kTileWidth], primitive_id[kTileWidth];
  Vec2 uv[kTileWidth];

  // Channels a G-buffer rendered without albedo or UVs leaves empty are not written.
  void stream_to(GBuffer& g, int x0, int y, int n) const {
    stream_copy(&g.position(x0, y), position, n * sizeof(Vec3));
    stream_copy(&g.normal(x0, y), normal, n * sizeof(Vec3));
    if (!g.albedo.empty()) stream_copy(&g.albedo(x0, y), albedo, n * sizeof(Vec3));
    stream_copy(&g.object_id(x0, y), object_id, n * sizeof(std::uint32_t));
    stream_copy(&g.primitive_id(x0, y), primitive_id, n * sizeof(std::uint32_t));
    if (!g.uv.empty()) stream_copy(&g.uv(x0, y), uv, n * sizeof(Vec2));
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
    trace_tile<N>(embree_scene(rs), ctx, cam, gen, s, hits);
    const bool extras = !g.albedo.empty() || !g.uv.empty();
    if (which == SurfaceNormal::Shading) {
      if (extras) shade_tile<SurfaceNormal::Shading, true>(rs, cam, basis, hits, g, s);
      else shade_tile<SurfaceNormal::Shading, false>(rs, cam, basis, hits, g, s);
    } else {
      if (extras) shade_tile<SurfaceNormal::Geometric, true>(rs, cam, basis, hits, g, s);
      else shade_tile<SurfaceNormal::Geometric, false>(rs, cam, basis, hits, g, s);
    }
  }
  _mm_sfence();  // the streamed rows are visible to whichever thread reads the G-buffer next
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
  const Frame basis = camera.basis();
  const RayGenerator gen(camera, basis);
  ProgressCounter counter(progress, static_cast<std::size_t>(w) * h);  // a primary ray per pixel
  // Primary rays of neighbouring pixels are coherent; every tile costs about the same, so TBB
  // hands each thread blocks of tiles.
  const detail::RayTiling tiling{kTileWidth, kTileHeight, RTC_INTERSECT_CONTEXT_FLAG_COHERENT, true};
  detail::for_each_ray_tile(rs, w, h, tiling, counter, [&]<int N>(RTCIntersectContext& ctx, const Tile& t) {
    render_tile<N>(rs, ctx, camera, basis, gen, options.normal, g, t);
    return static_cast<std::size_t>(t.x1 - t.x0) * static_cast<std::size_t>(t.y1 - t.y0);
  });
}

}  // namespace ao
