// SPDX-License-Identifier: Apache-2.0
// Which side of each open mesh a pixel's point lies on, for the cone method's open-surface
// voxelization (voxelize.h: a sheet stands for a slab on its far side from the point; a solid with
// holes seen from inside, for a slab outside its shell). Not installed.
//
// The side is the generalized winding number's (winding_number.h): behind a sheet where its w > 0,
// inside a solid with holes where sigma w > 1/2. A pixel on the open object itself is on the side
// the camera sees of its triangle. Every other object within reach of the open object is tested
// once at the corners of its box when the open object is a flat sheet: when they all agree, its
// pixels take that side; otherwise each pixel is tested at its point (through a coarse lattice of
// w where the lattice can tell, SideSetup::Open). A pixel of another object beyond a free rim of a
// sheet (out across its nearest rim within R_max by more than half its height off the rim
// triangle's plane) sees past the sheet: for it the sheet is its own two voxels (kBeyondRim). The
// pixels are then grouped by their sides (a key: flags per object of Scene::objects(),
// kBackSide | kBeyondRim), one voxel grid per key.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "ao/core/gbuffer.h"
#include "ao/methods/cone/voxelize.h"

namespace ao::cone_internal {

/// At most this many grids per frame (the all-front one included), each for at least
/// kMinSidePixels pixels or a thousandth of the covered ones, whichever is fewer: a grid costs a
/// voxelization (a solid with holes seen from inside, a slab around its shell within reach of
/// those pixels: 0.1-0.2 s for a 5,000-triangle scan at 512 columns, docs/methods/cone.md), which
/// a few pixels at a silhouette that see into a hole do not pay for. Other pixels are traced with
/// the all-front grid and counted (ConeResult::unresolved_pixels); the largest groups get the
/// grids.
inline constexpr int kMaxSideGrids = 8;
inline constexpr std::size_t kMinSidePixels = 32;

/// What does not depend on the camera: per open object, where it is, how to test a point, and the
/// votes of the other objects.
struct SideSetup {
  enum Vote : std::uint8_t { Front, Back, Mixed };
  struct Open {
    std::uint32_t object = 0;  // index in Scene::objects()
    Bounds3 reach;             // world box outside which no point can be behind it within 2 R_max
    Affine3 to_object;         // world -> mesh space (identity for a world-space mesh)
    bool instanced = false;
    int sign = 1;              // world w = sign x mesh w (mirror instances), times the orientation for solids
    double threshold = 0;      // behind: sign x w > threshold (0 for sheets, 1/2 for solids with holes)
    const MeshClosure* closure = nullptr;
    std::vector<Vec3> face;    // per triangle: its world normal (counter-clockwise, not unit)
    // A coarse lattice of sign x w - threshold over `reach` (non-flat meshes other objects vote
    // Mixed on): a point whose cell's 8 corners all lie on one side by kLatticeMargin takes that
    // side without an evaluation of w (w is harmonic off the mesh: it jumps only across the mesh,
    // which a cell whose corners agree does not cross, unless within a cell's width of a corner).
    Vec3 lattice_lo;
    float lattice_step = 0;
    int lx = 0, ly = 0, lz = 0;
    std::vector<float> lattice;
    // Sheets: their free rims (boundary edges that the surface does not go on across; world
    // space: the edge's ends, the unit direction out of the sheet across it in its triangle's
    // plane, and that triangle's unit normal), and cells at least R_max wide over `reach`, cell c
    // listing the rims whose boxes meet it in rim_list[rim_start[c], rim_start[c + 1]).
    struct Rim {
      Vec3 a, b, out, normal;
    };
    std::vector<Rim> rims;
    Vec3 rim_lo;
    float rim_cell = 0;
    int rx = 0, ry = 0, rz = 0;
    std::vector<std::uint32_t> rim_start, rim_list;
  };
  std::vector<Open> open;
  /// Per object of Scene::objects(): the open objects (index into `open`) whose back side its
  /// points are on (Back) or may be on (Mixed); objects on the front of every open object have none.
  std::vector<std::vector<std::pair<std::uint32_t, Vote>>> votes;
  float r_max = 0;
  /// Winding-number evaluations spent on the votes.
  std::size_t evaluations = 0;
};

/// The setup for `scene` and R_max (OpenMeshes::Winding only; empty `open` otherwise).
SideSetup make_side_setup(const Scene& scene, std::span<const MeshClosure> closure, float r_max);

/// The pixels grouped by side: keys[0] is all-front (empty: voxelize's default); key_of[pixel] is
/// an index into keys (0 for uncovered pixels). A setup with no open objects puts every pixel in
/// keys[0].
struct PixelSides {
  std::vector<std::vector<std::uint8_t>> keys;
  std::vector<std::uint8_t> key_of;
  std::size_t evaluations = 0;  ///< Winding numbers evaluated per pixel (Mixed votes, no triangle ids).
  std::size_t unresolved = 0;   ///< Pixels whose side got no grid (kMaxSideGrids, kMinSidePixels): traced as all-front.
  std::size_t back_pixels = 0;  ///< Covered pixels traced with a grid for the back side of an open object.
  std::size_t rim_pixels = 0;   ///< Covered pixels traced with a grid for points beyond a sheet's rim.
};
/// `front` is the grid built for the front of every object (its winding-number solids spare the
/// pixels outside them an evaluation of w).
PixelSides pixel_sides(const GBuffer& gbuffer, const Scene& scene, const SideSetup& setup, const VoxelGrid& front);

/// Where the pixels of side `key` can look: their points' box grown by 2 R_max (a slab R_max thick
/// reaches R_max past its face; a point's cones R_max). A grid for a few pixels (one side of a
/// small part of the scene) then leaves out the slabs that no cone of theirs can reach
/// (VoxelizeOptions::slab_region).
Bounds3 side_region(const GBuffer& gbuffer, const PixelSides& sides, std::size_t key, float r_max);

}  // namespace ao::cone_internal
