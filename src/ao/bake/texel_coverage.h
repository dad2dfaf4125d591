// SPDX-License-Identifier: Apache-2.0
// Which surface each texel of an AO map covers: the UV layout of a scene clipped exactly against
// the texel grid. Both bakers use it: the histogram baker for the exact normalisation (each
// texel's world-space area, the denominator of the paper's eq. 2), the ray-traced baker to spread
// its sample points over the texel's patch of surface.
//
// Conventions: texel (x, y) of a W x H map covers u in [x/W, (x+1)/W] and v in
// [1 - (y+1)/H, 1 - y/H]: v = 0 is the bottom row of the image (OpenGL / OBJ convention, which is
// how the mesh loader stores UVs). "Texel units" below are u * W and (1 - v) * H, so a texel is the
// unit square whatever the map's aspect ratio.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "ao/core/image.h"
#include "ao/core/math.h"
#include "ao/scene/mesh.h"

namespace ao {

/// Bakers write values per mesh vertex and per UV texel, which an instanced mesh (one set of UVs
/// and vertices, several placements with different AO) cannot hold: they take scenes whose every
/// mesh is placed once. Throws InputError naming the scene when `scene.instances` is not empty
/// (load with LoadOptions::flatten_instances, or flatten_instances()).
void require_no_instances(const Scene& scene);

/// One triangle's share of one texel.
struct TexelFragment {
  std::uint32_t mesh = 0;      ///< Index of the mesh in the scene.
  std::uint32_t triangle = 0;  ///< Triangle index within that mesh.
  float uv_area = 0;           ///< Area of triangle ∩ texel square, texel units (1 = the whole texel).
  float world_area = 0;        ///< The same piece of surface in world units^2.
};

/// A convex polygon in texel units (a triangle clipped to a square has at most 7 vertices).
struct ClipPolygon {
  Vec2 p[9];
  int n = 0;
  float area() const;  ///< Unsigned area.
};

/// A fragment and its triangle clipped to the texel.
struct TexelPiece {
  TexelFragment fragment;
  ClipPolygon polygon;
};

/// A triangle listed in a bin of the map (TexelCoverage): its box of texels, clamped to the map,
/// and its ratio of world area to UV area (constant over the triangle).
struct BinnedTriangle {
  std::uint32_t mesh = 0, triangle = 0;
  std::uint16_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;  ///< Texels x0 .. x1, y0 .. y1 (inclusive).
  double stretch = 0;                            ///< World units^2 per texel^2.
};

/// The UV layout of every mesh in a scene rasterised exactly onto a W x H grid: the surface each
/// texel covers, summed, and the triangles of each bin of kBin x kBin texels, from which a texel's
/// fragments are clipped again when asked (texel_fragments). The map's fragments are never held
/// all at once (a 1024^2 map of a 90k-triangle mesh has 0.8M of them): writing and reading them
/// cost more than clipping again.
struct TexelCoverage {
  static constexpr int kBin = 8;            ///< Texels per side of a bin.
  int width = 0;                            ///< W, texels.
  int height = 0;                           ///< H, texels.
  int bin_columns = 0;                      ///< Bins per row of bins, ceil(W / kBin).
  std::vector<std::uint32_t> bin_offsets;   ///< CSR: the triangles of bin b are binned[bin_offsets[b] .. bin_offsets[b+1]).
  std::vector<BinnedTriangle> binned;       ///< Per bin in mesh then triangle order; triangles with degenerate UVs left out.
  Image<float> world_area;                  ///< Per texel: world area of the surface it covers (eq. 2's denominator).
  Image<float> uv_area;                     ///< Per texel: covered fraction of the texel, summed over triangles (> 1 where charts overlap).
  Image<std::uint8_t> mask;                 ///< 1 where the texel covers some surface.
  std::size_t covered_texels = 0;           ///< Texels with mask = 1.
  std::size_t fragments = 0;                ///< (triangle, texel) pairs of non-zero area.
  std::size_t overlapping_texels = 0;       ///< Texels covered more than 1.01 times (overlapping charts).
  std::size_t degenerate_uv_triangles = 0;  ///< Triangles with surface area but (near) zero UV area: they get no texel.
  std::size_t outside_triangles = 0;        ///< Triangles partly outside [0,1]^2: the part outside is not baked.

  std::size_t texel_count() const { return static_cast<std::size_t>(width) * static_cast<std::size_t>(height); }
  /// One-line warnings for the user (overlaps, degenerate and out-of-range UVs); empty when clean.
  std::vector<std::string> warnings() const;
};

/// The fragments of texel `texel` of `cov` (computed on `scene`), each with its triangle clipped to
/// the texel, in mesh then triangle order, into `out` (emptied first): the triangles of the
/// texel's bin whose box holds it, clipped as compute_texel_coverage clipped them, so that their
/// areas are the ones it summed, bit for bit.
void texel_fragments(const Scene& scene, const TexelCoverage& cov, std::size_t texel, std::vector<TexelPiece>& out);

/// The fragments of every texel of bin (bx, by) of `cov` (computed on `scene`), each with its
/// triangle clipped to its texel: those of the bin's texel k (k = (y - by kBin) kBin + x - bx kBin)
/// are pieces[offsets[k] .. offsets[k + 1]), in mesh then triangle order, as texel_fragments gives
/// them. One pass over the bin's triangles, for a loop over the bin's texels.
struct BinFragments {
  std::array<std::uint32_t, TexelCoverage::kBin * TexelCoverage::kBin + 1> offsets{};
  std::vector<TexelPiece> pieces;
  std::vector<TexelPiece> scratch;       ///< The pieces in the order of the clips.
  std::vector<std::uint8_t> texel_of;    ///< The bin's texel of each piece of scratch.
  std::span<const TexelPiece> texel(int k) const {
    const auto i = static_cast<std::size_t>(k);
    return std::span(pieces).subspan(offsets[i], offsets[i + 1] - offsets[i]);
  }
};
void bin_fragments(const Scene& scene, const TexelCoverage& cov, int bx, int by, BinFragments& out);

/// fn(x, y, texel, fragments) for every covered texel of [x0, x1) x [y0, y1) of `cov` (computed on
/// `scene`), texel = y * width + x, with its fragments: bin by bin, each bin's fragments from one
/// pass over its triangles (bin_fragments into `bin`, the caller's scratch), its texels in rows.
template <class Fn>
void for_each_covered_texel(const Scene& scene, const TexelCoverage& cov, int x0, int y0, int x1, int y1, BinFragments& bin, Fn&& fn) {
  constexpr int kBin = TexelCoverage::kBin;
  for (int by = y0 / kBin; by * kBin < y1; ++by)
    for (int bx = x0 / kBin; bx * kBin < x1; ++bx) {
      bin_fragments(scene, cov, bx, by, bin);
      for (int y = std::max(y0, by * kBin); y < std::min(y1, (by + 1) * kBin); ++y)
        for (int x = std::max(x0, bx * kBin); x < std::min(x1, (bx + 1) * kBin); ++x) {
          const std::size_t texel = static_cast<std::size_t>(y) * static_cast<std::size_t>(cov.width) + static_cast<std::size_t>(x);
          if (cov.mask[texel]) fn(x, y, texel, bin.texel((y - by * kBin) * kBin + x - bx * kBin));
        }
    }
}

/// Clips every triangle of every mesh with UVs against the texel grid (Sutherland-Hodgman against
/// each texel square it overlaps). Meshes without UVs are skipped (they may still occlude).
/// `width` and `height` in [1, 16384]. Throws InputError when no mesh has UVs or all UV triangles
/// are degenerate.
TexelCoverage compute_texel_coverage(const Scene& scene, int width, int height);
/// A square `size` x `size` map.
TexelCoverage compute_texel_coverage(const Scene& scene, int size);

/// Texel-unit UV of vertex v of a mesh on a W x H map: (u * W, (1 - v) * H).
inline Vec2 texel_uv(const Mesh& m, std::uint32_t v, int width, int height) {
  return {m.uvs[v].x * static_cast<float>(width), (1.0f - m.uvs[v].y) * static_cast<float>(height)};
}

/// Triangle a b c clipped to the square [x, x+1] x [y, y+1].
ClipPolygon clip_to_texel(Vec2 a, Vec2 b, Vec2 c, int x, int y);

}  // namespace ao
