#include "ao/gbuffer/render_gbuffer.h"

#include <algorithm>
#include <cstddef>

#include "ao/reference/ray_tiles_internal.h"
#include "ao/simd/gbuffer_internal.h"

namespace ao {

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
  // Each tile is traced and written by the SIMD kernel layer (simd::render_gbuffer_tile).
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

}  // namespace ao
