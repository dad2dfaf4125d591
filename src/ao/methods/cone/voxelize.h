// SPDX-License-Identifier: Apache-2.0
// Solid binary voxelization by parity, after Eisemann & Decoret ("Single-pass GPU solid
// voxelization for real-time applications", GI 2008), as used by Dalla Favera & Celes, "Ambient
// occlusion using cone tracing with scene voxelization" (SIBGRAPI 2012), sec. III-B.
//
// The grid is a 2-D array of columns; each column is a bit mask of `depth_bits` voxels stored in
// ceil(depth_bits / 64) 64-bit words (bit k of the column is bit k % 64 of word k / 64). Every
// triangle, front and back faces alike, is rasterised at the column centres; each fragment XORs
// all bits of its column from its depth to the far end, so voxels inside closed objects end up 1
// (a voxel is inside when its centre is). We store the fragment as a single toggled bit and turn
// toggles into "XOR to the end" with one prefix-XOR scan per column at the end: the two are equal
// because XOR is associative and commutative.
//
// Two grids:
//  - World: columns along world y over the scene bounds, independent of the view.
//  - Eye: the paper's grid. Columns are the pixels of a lower-resolution copy of the camera's view
//    frustum; along a column, eq. 2 maps linear eye depth z to the voxel index
//    (z - z_nearest) / (z_far - z_nearest) * depth_bits, with z_nearest per column taken from the
//    G-buffer's nearest depth (the "local slice" of sec. III-B) and z_far the far side of the scene.
//
// Parity needs closed surfaces. analyze_closure (mesh_closure.h) tells per mesh what it stands for
// (MeshKind): closed (parity), a solid with holes (the solid where its generalized winding number w exceeds
// 1/2: parity with each hole closed by a fan, and w evaluated where a hole is not flat), or a sheet
// (a two-sided surface of no thickness). The cone method traces a sphere's occupied volume, so a
// surface of no thickness must stand for what it hides: a sheet becomes a slab `slab_thickness`
// thick on its far side from the points the grid is traced for. Which side that is depends on the
// point (`back`, per object: cone.cpp picks a grid per pixel by the sign of w), and for a point
// beyond a free rim of the sheet it is only its own two voxels (kBeyondRim). After the parity
// scan, each slab fragment ORs the voxels within `slab_thickness` behind it; faces steep to the
// columns (walls) become closed prisms of that thickness, whose union (they overlap where walls
// meet) is ORed in. A solid with holes traced from inside (seen through a hole) becomes a slab
// outside its shell. Columns whose parity still ends odd are counted and reported.
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "ao/core/gbuffer.h"
#include "ao/methods/cone/mesh_closure.h"
#include "ao/scene/mesh.h"

namespace ao {

/// The space the grid's columns live in.
enum class GridSpace {
  World,  ///< Columns along world +y over the scene bounds; bit 0 is the bottom.
  Eye,    ///< The paper's eye-space grid: columns are pixels of the view frustum, bit 0 is z_nearest.
};

/// Flags of an object's entry in voxelize_world's and voxelize_eye's `back`: which points of an
/// open object the grid is traced for.
inline constexpr std::uint8_t kBackSide = 1;   ///< Points on its back side (behind a sheet: w > 0;
                                               ///< inside a solid with holes: w > 1/2).
inline constexpr std::uint8_t kBeyondRim = 2;  ///< Sheets: points beyond one of its free rims, which
                                               ///< see past it: the sheet is its own two voxels,
                                               ///< no slab (cone_sides_internal.h, beyond_rim).

/// What to do with meshes that are not closed (have boundary edges).
enum class OpenMeshes {
  Winding,  ///< Default. By what each mesh is (MeshKind, from its winding number): a solid with
            ///< holes is the solid where w > 1/2 (see voxelize_world); a sheet is a slab on its far
            ///< side from the points traced (`back`); a solid with holes seen from inside is a slab
            ///< outside its shell.
  Slab,     ///< Sheets become slabs behind their fronts (one-sided, whatever side a point is on); solids
            ///< with holes are voxelized as they are (parity).
  Parity,   ///< Voxelize everything as it is: columns crossing an open mesh end odd (reported), and a
            ///< closed mesh around the camera (a room) is solid inside, as in the paper. The other two
            ///< modes take a room's outside for its solid (VoxelizeOptions::rooms).
};

/// Options of voxelize_world / voxelize_eye.
struct VoxelizeOptions {
  int columns = 512;              ///< World: columns along x and along z (columns x columns).
                                  ///< Eye: columns along the longer image side. [8, 4096].
  int depth_bits = 128;           ///< Voxels per column; a multiple of 32 in [32, 1024]. Paper: 128.
  OpenMeshes open_meshes = OpenMeshes::Winding;
  float slab_thickness = 0.0f;    ///< World units behind open faces; 0 = two voxels. >= 0. The cone
                                  ///< method uses R_max: under an open ground a cone then meets
                                  ///< solid as deep as it can look, as under a closed floor.
  /// World box the grid is traced in (empty: everywhere). Faces given slabs (sheets, a solid with
  /// holes seen from inside) whose slab cannot reach into it are left out: slabs are a union of
  /// one per face. Closed meshes and fans are always whole (parity needs them whole).
  Bounds3 slab_region;
  /// Per object (Scene::objects()): 1 for a closed mesh around the camera (closed_meshes_around), a
  /// room: what it encloses is air, its solid is outside. The world grid complements its parity and
  /// keeps a slab's thickness of solid around it (not with open_meshes=parity); an eye grid's
  /// columns start inside it, where parity is already right. Empty: none.
  std::vector<std::uint8_t> rooms;

  /// Throws InputError naming the bad field.
  void validate() const;
};

/// Numbers for --json.
struct VoxelStats {
  std::size_t triangles = 0;       ///< Triangles rasterised (after clipping and culling).
  std::size_t fragments = 0;       ///< Column-centre hits.
  std::size_t odd_columns = 0;     ///< Columns whose parity ends at 1: open or leaky geometry.
  std::size_t open_meshes = 0;     ///< Sheets (MeshClosure::open_surface).
  std::size_t holed_meshes = 0;    ///< Solids with holes (MeshClosure::holed).
  std::size_t holes = 0;           ///< Their holes.
  std::size_t capped_meshes = 0;   ///< Objects of solids with holes voxelized as their winding-number solid.
  std::size_t back_objects = 0;    ///< Open objects voxelized for points on their back side (`back`).
  std::size_t winding_evaluations = 0;     ///< Voxels where w was evaluated (next to fans over holes that are not flat).
  std::size_t winding_voxels_changed = 0;  ///< Of those, voxels where w > 1/2 and the fans' parity differ.
  std::size_t boundary_edges = 0;  ///< Over all meshes.
  std::size_t set_voxels = 0;      ///< Solid voxels in the finished grid.
};

/// A binary voxel grid of columns of bits, and the map from space to voxel coordinates.
/// Voxel coordinates are continuous: column (i, j) covers [i, i+1) x [j, j+1), voxel k covers
/// [k, k+1) along the column; the voxel's centre is at +0.5.
struct VoxelGrid {
  GridSpace space = GridSpace::World;
  int nx = 0, ny = 0;       ///< Columns.
  int depth_bits = 0;       ///< Voxels per column.
  int words = 0;            ///< 64-bit words per column = ceil(depth_bits / 64).
  /// Column (i, j) is words [(j * nx + i) * words, ... + words). In pixel storage: a grid of 2 MiB
  /// and more (512 x 512 columns of 128 bits is 4 MiB) is advised as transparent huge pages, so a
  /// fresh grid faults in by a couple of faults rather than a thousand.
  std::vector<std::uint64_t, detail::DefaultInitAllocator<std::uint64_t>> bits;

  // World grid: x -> i, z -> j, y -> k.
  Vec3 origin;              ///< World point of voxel coordinate (0, 0, 0).
  Vec3 voxel_size;          ///< World size of a voxel along (i, j, k) = (world x, world z, world y).

  // Eye grid.
  Camera camera;            ///< The G-buffer's camera; a column is a block of its pixels.
  float pixels_per_column_x = 1, pixels_per_column_y = 1;
  float z_far = 0;          ///< Linear depth of the far end of every column.
  std::vector<float> z_near;        ///< Per column: z_nearest of eq. 2 (linear depth, world units).
  std::vector<float> voxels_per_unit;  ///< Per column: depth_bits / (z_far - z_nearest).

  // Coarse occupancy for empty-space skipping: block (bi, bj) holds the OR of the columns
  // [bi * kBlock, +kBlock) x [bj * kBlock, +kBlock), `words` words like a column.
  static constexpr int kBlock = 8;
  int bnx = 0, bny = 0;
  std::vector<std::uint64_t> block_bits;
  const std::uint64_t* block(int bi, int bj) const { return block_bits.data() + (static_cast<std::size_t>(bj) * static_cast<std::size_t>(bnx) + static_cast<std::size_t>(bi)) * static_cast<std::size_t>(words); }

  // Windowed coarse occupancy for O(1) empty-space skipping. Cells are kCellXY x kCellXY columns x
  // cell_bits voxels (cell_bits: the smallest power of two that gives at most 64 cells per column).
  // window[(cj * dnx + ci) * (kWindowCap + 1) + w], w in [0, kWindowCap] (one cache line per cell),
  // is a 64-bit mask over the cells along the column: bit ck is set when a cell (ci', cj', ck) with
  // ci <= ci' <= ci + w and cj <= cj' <= cj + w (the square window of w + 1 cells anchored at
  // (ci, cj), clipped to the grid) holds a solid voxel. A box of columns [x0, x1] x [y0, y1] lies in
  // the window anchored at its lowest cell with w = the larger of its spans in cells. Blocks
  // (above) are 2 x 2 cells.
  static constexpr int kCellXY = 4;
  static constexpr int kWindowCap = 7;
  int dnx = 0, dny = 0;
  int cell_bits = 0, cell_shift = 0;  ///< cell_bits = 1 << cell_shift.
  std::vector<std::uint64_t> window;
  std::uint64_t window_mask(int w, int ci, int cj) const { return window[(static_cast<std::size_t>(cj) * static_cast<std::size_t>(dnx) + static_cast<std::size_t>(ci)) * (kWindowCap + 1) + static_cast<std::size_t>(w)]; }

  /// Words of column (i, j), which must be inside the grid.
  const std::uint64_t* column(int i, int j) const { return bits.data() + (static_cast<std::size_t>(j) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(i)) * static_cast<std::size_t>(words); }
  /// Bit k of column (i, j).
  bool voxel(int i, int j, int k) const { return (column(i, j)[k >> 6] >> (k & 63)) & 1u; }
  /// Set voxels in the whole grid.
  std::size_t count_set() const;
};

/// Set bits among bits [k0, k1) of a column of words (k0 and k1 are clamped to [0, 64 * words]).
/// Whole words are counted with hardware popcount, partial ones through a mask.
inline int count_bits(const std::uint64_t* column, int words, int k0, int k1) {
  k0 = k0 < 0 ? 0 : k0;
  k1 = k1 > 64 * words ? 64 * words : k1;
  if (k1 <= k0) return 0;
  const int w0 = k0 >> 6, w1 = (k1 - 1) >> 6;
  const std::uint64_t lo_mask = ~std::uint64_t{0} << (k0 & 63);
  const std::uint64_t hi_mask = ~std::uint64_t{0} >> (63 - ((k1 - 1) & 63));
  if (w0 == w1) return std::popcount(column[w0] & lo_mask & hi_mask);
  int n = std::popcount(column[w0] & lo_mask) + std::popcount(column[w1] & hi_mask);
  for (int w = w0 + 1; w < w1; ++w) n += std::popcount(column[w]);
  return n;
}

/// True when any of bits [k0, k1) of a column is set (k0, k1 clamped as in count_bits).
inline bool any_bits(const std::uint64_t* column, int words, int k0, int k1) {
  k0 = k0 < 0 ? 0 : k0;
  k1 = k1 > 64 * words ? 64 * words : k1;
  if (k1 <= k0) return false;
  const int w0 = k0 >> 6, w1 = (k1 - 1) >> 6;
  const std::uint64_t lo_mask = ~std::uint64_t{0} << (k0 & 63);
  const std::uint64_t hi_mask = ~std::uint64_t{0} >> (63 - ((k1 - 1) & 63));
  if (w0 == w1) return (column[w0] & lo_mask & hi_mask) != 0;
  if ((column[w0] & lo_mask) | (column[w1] & hi_mask)) return true;
  for (int w = w0 + 1; w < w1; ++w)
    if (column[w]) return true;
  return false;
}

/// voxelize_world's grid frame without its bits (space, nx, ny, depth_bits, words, origin,
/// voxel_size) for `scene` and options `o`: the scene's bounds padded by a voxel, and by the slab
/// thickness beside and below them (`slab_beside`) and above them (`slab_above`), the scene's
/// ground (the height of its largest area of horizontal faces facing up) on a boundary between voxels and between
/// the coarse occupancy's cells. `slab_out`: the slab thickness (options' or two voxels). Shared
/// with the GPU's voxelization (cone_gpu.cpp), whose grids are the CPU's bit for bit.
VoxelGrid world_grid_layout(const Scene& scene, const VoxelizeOptions& o, bool slab_beside, bool slab_above, float* slab_out = nullptr);


/// World-space grid of options.columns x options.columns columns over `scene`'s bounds, columns
/// along world y.
///
/// Solids with holes (OpenMeshes::Winding): the solid is where the mesh's generalized winding
/// number w (Jacobson, Kavan, Sorkine-Hornung, "Robust inside-outside segmentation using
/// generalized winding numbers", SIGGRAPH 2013; winding_number.h) exceeds 1/2. Each hole is closed
/// by a fan C of triangles from its boundary edges to its centroid; the mesh plus C is closed, so
/// its winding number is its parity indicator chi (what the parity pass computes exactly), and
/// since w is a sum over triangles, w_mesh = chi - w_C. Off a flat fan |w_C| < 1/2 (the fan lies in
/// a plane and subtends less than a hemisphere), so there w_mesh > 1/2 exactly where chi = 1. Off
/// the convex hull of a fan that is not flat |w_C| < 1/2 as well (the fan is seen within a
/// hemisphere; this assumes the hole's outline seen from there does not cross itself), and inside
/// it the two differ only in the pocket between the fan and the surface w = 1/2 that spans the
/// hole; w is evaluated there (from each fan fragment along its column, voxelize.cpp). Objects are
/// assumed not to overlap there (as parity assumes). The bounds are padded by a voxel, and below
/// and at the sides by the slab thickness when there are slabs. `closure` comes from
/// analyze_closure(scene). `back`: per object of Scene::objects(), the points the grid is for
/// (kBackSide, kBeyondRim; 0: on its front side); empty = the front of every object. Only
/// OpenMeshes::Winding reads it.
VoxelGrid voxelize_world(const Scene& scene, std::span<const MeshClosure> closure, const VoxelizeOptions& options, VoxelStats* stats = nullptr,
                         std::span<const std::uint8_t> back = {});

/// The paper's eye-space grid for the G-buffer's camera (which must carry its world placement):
/// columns are blocks of pixels, z_nearest per column is the smallest G-buffer depth in its block
/// (eq. 2, local slice), z_far the farthest corner of the scene's bounds. Geometry outside the view
/// frustum is not voxelized; triangles are clipped at a near plane in front of the eye.
/// Open meshes and `back` as for voxelize_world.
VoxelGrid voxelize_eye(const Scene& scene, std::span<const MeshClosure> closure, const GBuffer& gbuffer, const VoxelizeOptions& options,
                       VoxelStats* stats = nullptr, std::span<const std::uint8_t> back = {});

}  // namespace ao
