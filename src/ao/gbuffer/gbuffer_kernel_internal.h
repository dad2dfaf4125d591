// SPDX-License-Identifier: Apache-2.0
// Kernel of the G-buffer pass (gbuffer/render_gbuffer.h), written once for every SIMD target
// (gbuffer.cpp): one tile's primary rays traced in Embree packets and its rows of every channel
// streamed to the images. render_gbuffer sizes the images and hands out the tiles.
#pragma once

#include <embree3/rtcore.h>

#include "ao/core/camera.h"
#include "ao/core/gbuffer.h"
#include "ao/core/math.h"
#include "ao/core/parallel.h"
#include "ao/reference/ray_scene.h"

namespace ao::simd {

/// Tiles are at most this wide and high, pixels (TBB hands each thread blocks of tiles).
inline constexpr int kGBufferTileWidth = 64, kGBufferTileHeight = 16;

/// World-space direction through pixel centre (x + 0.5, y + 0.5) as origin + x * dx + y * dy: the
/// per-pixel work of Camera::camera_direction with the trigonometry done once per image.
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

/// What every tile of one G-buffer shares. The images of `g` have the camera's size already (albedo
/// and uv: or are empty, then they are not written).
struct GBufferTileJob {
  const RayScene* scene = nullptr;
  const Camera* camera = nullptr;
  Frame basis;                 ///< camera->basis().
  RayGenerator rays;           ///< Of camera and basis.
  SurfaceNormal normal = SurfaceNormal::Shading;
  GBuffer* g = nullptr;
};

/// Traces the primary rays of tile t (at most kGBufferTileWidth wide) in packets of packet_width
/// rays (16, 8, 4 or 1: the tile loop's, detail::for_each_ray_tile) with the intersect context ctx,
/// and writes its pixels of every channel of job.g, as render_gbuffer states, with non-temporal
/// stores followed by a fence.
void render_gbuffer_tile(const GBufferTileJob& job, int packet_width, RTCIntersectContext& ctx, const Tile& t);

}  // namespace ao::simd
