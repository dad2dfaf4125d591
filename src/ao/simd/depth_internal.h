// SPDX-License-Identifier: Apache-2.0
// Kernel of the G-buffer's depth plane (core/gbuffer.h: depth_plane), which every depth-reading
// pass builds once from the positions and ids, written once for every SIMD target (depth.cpp).
#pragma once

#include <cstdint>

#include "ao/core/math.h"

namespace ao::simd {

/// For the tile [x0, x1) x [y0, y1) of images `width` pixels wide: out = -position.z (the linear
/// depth) where object_id != 0, +infinity elsewhere.
void depth_plane_tile(const Vec3* position, const std::uint32_t* object_id, int width, int x0, int x1, int y0, int y1, float* out);

/// A G-buffer as the kernels that sample its depth plane see it (Alchemy, GTAO): the plane, the
/// normals and ids, and the camera rays through pixel centres, ray(x, y) = (ray_ax (x + 1/2) +
/// ray_bx, ray_ay (y + 1/2) + ray_by, -1), so a sample's camera-space point is its depth times its
/// ray: one 4-byte gather per sample instead of three from the 12-byte positions.
struct DepthView {
  const float* depth = nullptr;              ///< width * height linear depths, +infinity on background.
  const float* normal = nullptr;             ///< width * height unit normals, xyz triples, camera space.
  const std::uint32_t* object_id = nullptr;  ///< width * height; 0: uncovered.
  int width = 0, height = 0;
  float ray_ax = 0, ray_bx = 0, ray_ay = 0, ray_by = 0;
  float px_per_unit = 1;  ///< Pixels per unit of x/(-z) on both axes: 0.5 height / tan(fov / 2).
};

/// The view of a width x height G-buffer seen by a camera of tan(fov / 2) = `tan_half_fov` and
/// width / height = `aspect`.
inline DepthView depth_view(const float* depth, const float* normal, const std::uint32_t* object_id, int width, int height,
                            float tan_half_fov, float aspect) {
  const float t = tan_half_fov;
  DepthView v;
  v.depth = depth, v.normal = normal, v.object_id = object_id;
  v.width = width, v.height = height;
  v.ray_ax = 2.0f * t * aspect / static_cast<float>(width), v.ray_bx = -t * aspect;
  v.ray_ay = -2.0f * t / static_cast<float>(height), v.ray_by = t;
  v.px_per_unit = 0.5f * static_cast<float>(height) / t;
  return v;
}

}  // namespace ao::simd
