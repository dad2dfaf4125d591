// Kernel of the G-buffer's depth plane (core/gbuffer.h: depth_plane), which every depth-reading
// pass builds once from the positions and ids, written once for every SIMD target (depth.cpp).
#pragma once

#include <cstdint>

#include "ao/core/math.h"

namespace ao::simd {

/// For the tile [x0, x1) x [y0, y1) of images `width` pixels wide: out = -position.z (the linear
/// depth) where object_id != 0, +infinity elsewhere.
void depth_plane_tile(const Vec3* position, const std::uint32_t* object_id, int width, int x0, int x1, int y0, int y1, float* out);

}  // namespace ao::simd
