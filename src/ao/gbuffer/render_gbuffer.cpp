#include "ao/gbuffer/render_gbuffer.h"

#include <array>

#include "ao/core/parallel.h"
#include "ao/reference/packets_internal.h"

namespace ao {

namespace {

constexpr int kTile = 32;  // pixels per tile side: a tile is one TBB task

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

// Writes the G-buffer entry of pixel (x, y) for a hit on triangle `prim` of mesh `geom` at
// barycentric (u, v), or the background values when geom is invalid.
void shade_hit(const Scene& scene, const Camera& cam, const Frame& basis, SurfaceNormal which, GBuffer& g, int x, int y, unsigned geom,
               unsigned prim, float u, float v) {
  if (geom == RTC_INVALID_GEOMETRY_ID) {
    g.position(x, y) = {};
    g.depth(x, y) = kInfinity;
    g.normal(x, y) = {};
    g.albedo(x, y) = {};
    g.object_id(x, y) = 0;
    g.primitive_id(x, y) = 0;
    g.coverage(x, y) = 0;
    g.uv(x, y) = {};
    return;
  }
  const Mesh& m = scene.meshes[geom];
  const std::uint32_t i0 = m.indices[3 * prim], i1 = m.indices[3 * prim + 1], i2 = m.indices[3 * prim + 2];
  const float w = 1.0f - u - v;
  // Interpolating the vertices puts the point on the triangle to float rounding, which is more
  // accurate than eye + t * direction far from the camera.
  const Vec3 p = m.positions[i0] * w + m.positions[i1] * u + m.positions[i2] * v;
  const Vec3 pc = basis.to_local(p - cam.eye);
  Vec3 ng = basis.to_local(normalize(cross(m.positions[i1] - m.positions[i0], m.positions[i2] - m.positions[i0])));
  // Both sides of a surface can be seen (open meshes, rooms): AO is for the side facing the
  // viewer, so turn the geometric normal towards the camera and the shading normal onto its side.
  if (dot(ng, pc) > 0) ng = -ng;
  Vec3 n = ng;
  if (which == SurfaceNormal::Shading) {
    n = basis.to_local(normalize(m.normals[i0] * w + m.normals[i1] * u + m.normals[i2] * v));
    if (dot(n, ng) < 0) n = -n;
    if (!(length(n) > 0.5f)) n = ng;
  }
  g.position(x, y) = pc;
  g.depth(x, y) = -pc.z;
  g.normal(x, y) = n;
  g.albedo(x, y) = m.albedo;
  g.object_id(x, y) = geom + 1;
  g.primitive_id(x, y) = prim;
  g.coverage(x, y) = 1;
  if (!m.uvs.empty()) {
    const Vec2 t0 = m.uvs[i0], t1 = m.uvs[i1], t2 = m.uvs[i2];
    g.uv(x, y) = {t0.x * w + t1.x * u + t2.x * v, t0.y * w + t1.y * u + t2.y * v};
  } else {
    g.uv(x, y) = {};
  }
}

template <int N>
void render_tile(const RayScene& rs, const Camera& cam, const Frame& basis, const RayGenerator& gen, SurfaceNormal which, GBuffer& g,
                 const Tile& t) {
  detail::flush_denormals_to_zero();
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  const Scene& scene = rs.scene();
  const RTCScene bvh = embree_scene(rs);
  if constexpr (N == 1) {
    for (int y = t.y0; y < t.y1; ++y)
      for (int x = t.x0; x < t.x1; ++x) {
        const Vec3 d = gen(x, y);
        RTCRayHit rh{};
        rh.ray = {cam.eye.x, cam.eye.y, cam.eye.z, 0.0f, d.x, d.y, d.z, 0.0f, kInfinity, 0xffffffffu, 0, 0};
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(bvh, &ctx, &rh);
        shade_hit(scene, cam, basis, which, g, x, y, rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v);
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
        for (int k = 0; k < N; ++k)
          if (valid[k])
            shade_hit(scene, cam, basis, which, g, bx + k % bw, by + k / bw, rh.hit.geomID[k], rh.hit.primID[k], rh.hit.u[k], rh.hit.v[k]);
      }
  }
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
  g.depth.resize(w, h);
  g.normal.resize(w, h);
  g.albedo.resize(w, h);
  g.object_id.resize(w, h);
  g.coverage.resize(w, h);
  g.uv.resize(w, h);
  g.primitive_id.resize(w, h);
  g.camera = camera;
  g.direct = Image<Vec3>();  // belongs to the lighting of the previous view: render_direct_light makes a new one
  const Frame basis = camera.basis();
  const RayGenerator gen(camera, basis);
  ProgressCounter counter(progress, static_cast<std::size_t>(camera.width) * camera.height);
  detail::dispatch_packet_width(rs.native_packet_width(), [&]<int N>() {
    parallel_for_tiles(camera.width, camera.height, kTile, [&](const Tile& t) {
      render_tile<N>(rs, camera, basis, gen, options.normal, g, t);
      counter.add(static_cast<std::size_t>(t.x1 - t.x0) * (t.y1 - t.y0));
    });
  });
}

}  // namespace ao
