// SPDX-License-Identifier: Apache-2.0
// Where a secondary ray starts: a surface point moved off its own triangle by a distance that
// follows the float precision of the coordinates involved, so it works at any scene scale and at
// any distance from the world origin (after Waechter & Binder, "A Fast and Robust Method for
// Avoiding Self-Intersection", Ray Tracing Gems, ch. 6: offset along the geometric normal by a
// few float spacings of the point's own coordinates).
//
// Why a multiple of the float spacing of `magnitude` is enough: the hit point is known to a few
// ulps of its coordinates (barycentric interpolation of the vertices, and for G-buffer pixels a
// camera-space round trip through the eye position), and Embree's triangle test computes
// t * (d . Ng) = (v0 - o) . Ng, whose rounding is a few ulps of the vertex and origin coordinates.
// Both errors are bounded by eps * magnitude with `magnitude` the largest absolute coordinate of
// the triangle's vertices, the point and (for the G-buffer) the eye. kRayOffsetUlps spacings clear
// them with a margin; the value is measured in tests/reference/ray_offset_test.cpp and
// docs/methods/raytraced.md ("Ray offset").
#pragma once

#include <algorithm>
#include <cmath>

#include "ao/core/math.h"
#include "ao/scene/mesh.h"

namespace ao {

/// Float spacings of the coordinate magnitude a ray origin moves along the geometric normal.
inline constexpr float kRayOffsetUlps = 64.0f;

/// Largest absolute coordinate of p.
inline float max_abs_coordinate(Vec3 p) { return std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}); }

/// Largest absolute coordinate of triangle `tri`'s vertices in mesh `m`: the scale of the float
/// errors of points on it and of ray tests against it.
inline float triangle_magnitude(const Mesh& m, std::size_t tri) {
  const std::uint32_t* i = &m.indices[3 * tri];
  return std::max({max_abs_coordinate(m.positions[i[0]]), max_abs_coordinate(m.positions[i[1]]), max_abs_coordinate(m.positions[i[2]])});
}

/// Distance a ray origin moves off a surface whose coordinates (and those of the computation
/// that produced the point) are at most `magnitude` in absolute value: kRayOffsetUlps x 2^-23 x
/// magnitude (2^-23 x m bounds the spacing of floats of magnitude m).
inline float ray_offset_distance(float magnitude) { return kRayOffsetUlps * 0x1p-23f * magnitude; }

/// Largest absolute coordinate of `b`: the offset scale for rays whose triangle is not known
/// (a conservative bound for every point of the scene).
inline float bounds_magnitude(const Bounds3& b) { return std::max(max_abs_coordinate(b.lo), max_abs_coordinate(b.hi)); }

/// Offset scale for a ray from point p when its triangle is not known (the single-point
/// estimates): the largest coordinate of p and of the scene bounds `b`.
inline float point_magnitude(Vec3 p, const Bounds3& b) { return std::max(max_abs_coordinate(p), bounds_magnitude(b)); }

/// p moved along the unit geometric normal `ng` (on the side the ray leaves from) by
/// ray_offset_distance(magnitude).
inline Vec3 offset_ray_origin(Vec3 p, Vec3 ng, float magnitude) { return p + ng * ray_offset_distance(magnitude); }

}  // namespace ao
