// SPDX-License-Identifier: Apache-2.0
// Internal: a triangle mesh as Embree quads, two triangles that share an edge per quad, for the
// quad BVH a RayScene builds with BvhOptions::quads. Embree intersects a quad (v0, v1, v2, v3) as
// the two triangles (v0, v1, v3) and (v2, v3, v1), and a quad whose last two indices are equal as
// the one triangle (v0, v1, v2); so the quads hold exactly the mesh's triangles, in about half the
// primitives.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "ao/scene/mesh.h"

namespace ao::detail {

struct TrianglePairs {
  std::vector<std::uint32_t> quads;      ///< Four vertex indices per quad (Embree's RTC_FORMAT_UINT4).
  std::vector<std::uint32_t> triangles;  ///< Two per quad: the mesh triangles of its halves (v0, v1, v3) and (v2, v3, v1); equal for a lone triangle.
  std::size_t quad_count() const { return quads.size() / 4; }
  std::size_t paired_triangles = 0;      ///< Triangles that share their quad with another.
};

/// Meshes pair_triangles takes have fewer triangles than this (it numbers edges in 32 bits).
inline constexpr std::size_t kMaxPairedTriangles = std::size_t{1} << 30;

/// Pairs the triangles of `m` (fewer than kMaxPairedTriangles) into quads. Two triangles pair across an edge they share with
/// opposite directions (both wound the same way seen from one side), the edge's ends compared by
/// position, so the two sides of a UV seam, whose vertices are split, still pair; an edge of more
/// than two triangles pairs any two of them with opposite directions. Among the candidate pairs, those whose
/// quad has the smallest bounding box relative to its two triangles' boxes are taken first
/// (greedy), since a quad's box is what the BVH's leaves bound. Deterministic. Each quad's first
/// half keeps its triangle's winding and so does its second: the quad's halves are the mesh's
/// triangles exactly, vertex for vertex.
TrianglePairs pair_triangles(const Mesh& m);

/// The mesh triangle of a hit on quad `quad` with Embree's hit coordinates (u, v): Embree reports
/// the second half's (1 - u', 1 - v'), so u + v <= 1 is the first half (the diagonal belongs to
/// both; the first is taken).
inline std::uint32_t quad_hit_triangle(const TrianglePairs& p, std::uint32_t quad, float u, float v) {
  return p.triangles[2 * static_cast<std::size_t>(quad) + (u + v > 1.0f ? 1 : 0)];
}

}  // namespace ao::detail
