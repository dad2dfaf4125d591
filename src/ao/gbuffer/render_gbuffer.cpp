#include "ao/gbuffer/render_gbuffer.h"

#include <algorithm>
#include <cstddef>

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include "ao/core/parallel.h"
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
  const simd::GBufferTileJob job{&rs, &camera, basis, simd::RayGenerator(camera, basis), options.normal, rs.native_packet_width(), &g};
  ProgressCounter counter(progress, static_cast<std::size_t>(camera.width) * camera.height);
  // The range is of tile indices, so the tiles are the same however TBB splits it. TBB's auto
  // partitioner hands each thread a few blocks of tiles (splitting further only when a thread runs
  // dry) instead of one task per tile: fewer task switches.
  constexpr int tw = simd::kGBufferTileWidth, th = simd::kGBufferTileHeight;
  const int columns = (camera.width + tw - 1) / tw, rows = (camera.height + th - 1) / th;
  tbb::parallel_for(tbb::blocked_range2d<int>(0, rows, 0, columns), [&](const tbb::blocked_range2d<int>& r) {
    for (int ty = r.rows().begin(); ty < r.rows().end(); ++ty)
      for (int tx = r.cols().begin(); tx < r.cols().end(); ++tx) {
        const int x0 = tx * tw, y0 = ty * th, x1 = std::min(x0 + tw, camera.width), y1 = std::min(y0 + th, camera.height);
        simd::render_gbuffer_tile(job, x0, y0, x1, y1);
        counter.add(static_cast<std::size_t>(x1 - x0) * (y1 - y0));
      }
  });
}

}  // namespace ao
