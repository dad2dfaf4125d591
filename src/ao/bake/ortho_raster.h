// SPDX-License-Identifier: Apache-2.0
// Orthographic z-buffered rasterisation with back-face culling: stage 1 of the per-texel AO paper
// (McGraw & Sowers, sec. 3, "Render from light direction w"), on the CPU. The output is a
// visibility buffer (depth + triangle id per pixel); the histogram baker turns it into (u, v) and
// (w . n)|J| per pixel, exactly what the paper's fragment program writes.
#pragma once

#include <cstdint>
#include <vector>

#include "ao/core/image.h"
#include "ao/core/math.h"
#include "ao/scene/mesh.h"

namespace ao {

/// All meshes of a scene flattened into one triangle list, built once per bake.
struct RasterMesh {
  std::vector<Vec3> positions;           ///< World units.
  std::vector<Vec3> normals;             ///< Unit, per vertex (interpolated for the cosine, as the paper's FP does).
  std::vector<Vec2> uvs;                 ///< Texel units (see texel_coverage.h); (0,0) for meshes without UVs.
  std::vector<std::uint32_t> indices;    ///< Three per triangle, into the flattened vertex arrays.
  std::vector<std::uint8_t> has_uv;      ///< Per triangle: 1 if its mesh has UVs (only those are scattered).
  std::vector<float> stretch;            ///< Per triangle: world area / UV area (texel units); 0 if degenerate or no UVs.
  std::vector<std::uint32_t> mesh_of;    ///< Per triangle: mesh index in the scene.
  std::vector<std::uint32_t> first_vertex;  ///< Per mesh: index of its first vertex in the flattened arrays.
  Vec3 center;                           ///< Centre of the bounding sphere.
  float radius = 0;                      ///< Bounding-sphere radius, world units.
  double surface_area = 0;               ///< Sum of triangle areas, world units^2.

  std::size_t triangle_count() const { return indices.size() / 3; }
};

/// Flattens a validated scene. `map_width` x `map_height` scales UVs to texel units (0: no map, UVs unused).
RasterMesh make_raster_mesh(const Scene& scene, int map_width, int map_height);

/// An orthographic view along -w. Pixel (i, j) has its centre at image coordinates
/// (i + 0.5, j + 0.5); image x = dot(p - origin, t) / pixel_size, y = dot(p - origin, b) / pixel_size,
/// depth = dot(p, w) (larger is nearer the light).
struct OrthoView {
  Frame frame;             ///< frame.n = w, the direction towards the light.
  Vec3 origin;             ///< World point at image coordinate (0, 0).
  float pixel_size = 1;    ///< World units per pixel.
  int width = 0, height = 0;
};

/// A view of the whole bounding sphere along -w, its pixel grid shifted by `jitter` (in pixels,
/// [0,1)^2) so that the grids of different directions sample the surface at different offsets.
OrthoView make_ortho_view(const RasterMesh& mesh, Vec3 w, float pixel_size, Vec2 jitter);

/// Per-direction scratch: projected vertices and the visibility buffer. Reused across directions.
struct RasterTarget {
  std::vector<float> px, py, pz;    ///< Projected vertices: image x, y and depth.
  Image<float> depth;               ///< Depth of the nearest front face; -infinity where empty.
  Image<std::uint32_t> id;          ///< 1 + triangle index of the visible face; 0 where empty.
};

/// Projects the mesh and z-buffers its front faces (those whose counter-clockwise side faces w;
/// the paper's back-face culling). A pixel is covered when its centre is inside the triangle;
/// centres exactly on an edge go to one of the two triangles sharing it (a fixed tie rule), so
/// a closed surface covers each pixel exactly once per layer.
void rasterize(const RasterMesh& mesh, const OrthoView& view, RasterTarget& target);

}  // namespace ao
