// SPDX-License-Identifier: Apache-2.0
// Kernels of the outside-in baker (McGraw & Sowers, "Hardware Accelerated Per-Texel Ambient
// Occlusion Mapping", 2008; bake/histogram.cpp), compiled once for every SIMD target
// (histogram.cpp): per direction, stage 1's orthographic z-buffered rasterisation with back-face
// culling (bake/ortho_raster.h) and stage 2's histogram scatter of eq. 7-8. Scalar code per
// triangle and per pixel; what the targets give it is their instruction set (VEX encoding,
// SSE4.1's rounding), so the results are the same bits on every target.
#pragma once

#include <cstddef>
#include <cstdint>

#include "ao/core/math.h"

namespace ao::simd {

/// A mesh seen along -frame.n: vertices and triangles (three indices each).
struct RasterInput {
  const Vec3* positions = nullptr;
  std::size_t vertices = 0;
  const std::uint32_t* indices = nullptr;
  std::size_t triangles = 0;
  Frame frame;              ///< frame.n = w, towards the light.
  Vec3 origin;              ///< World point at image coordinate (0, 0).
  float pixel_size = 1;     ///< World units per pixel.
  int width = 0, height = 0;
};

/// Projects the vertices (px, py: image coordinates, pz: depth = p . w, larger nearer the light)
/// and z-buffers the front faces into `depth` (-infinity where empty, written here) and `ids` (1 +
/// triangle, 0 where empty): a pixel is covered when its centre is inside the triangle, centres
/// exactly on an edge go to one of its two triangles (a fixed tie rule).
void rasterize_front_faces(const RasterInput& in, float* px, float* py, float* pz, float* depth, std::uint32_t* ids);

/// Stage 2 for one direction (eq. 7-8): every visible pixel of a triangle with UVs adds (w . n)|J|
/// (times the triangle's stretch over the pixel area with `area_norm`), clamped to `max_weight`,
/// in fixed point (times `fixed_scale`), to the texel holding its (u, v); with `bent` also that
/// weight / 1024 times the direction in 1/1024 (bx, by, bz) to the texel's bent-normal sums.
struct ScatterInput {
  const std::uint32_t* ids = nullptr;  ///< The view's visibility buffer.
  const float* px = nullptr;           ///< Projected vertices.
  const float* py = nullptr;
  int view_width = 0, view_height = 0;
  const std::uint32_t* indices = nullptr;
  const std::uint8_t* has_uv = nullptr;  ///< Per triangle.
  const float* stretch = nullptr;        ///< Per triangle: world area / UV area.
  const Vec2* uvs = nullptr;             ///< Per vertex, texel units.
  const float* cos_v = nullptr;          ///< Per vertex: w . n.
  int map_width = 0, map_height = 0;
  float pixel_size = 1;
  bool area_norm = true;
  float max_weight = 64;
  double fixed_scale = 1048576.0;
  bool bent = false;
  std::int64_t bx = 0, by = 0, bz = 0;
};

/// Adds the direction's pixels to sum (per texel) and bent (3 per texel, with `bent`); returns the
/// number of fragments scattered.
std::uint64_t scatter_histogram(const ScatterInput& in, std::uint64_t* sum, std::int64_t* bent);

}  // namespace ao::simd
