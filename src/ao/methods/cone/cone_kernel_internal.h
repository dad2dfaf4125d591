// SPDX-License-Identifier: Apache-2.0
// Kernel of voxel cone traced AO on the world grid (Dalla Favera and Celes, "Ambient occlusion
// using cone tracing with scene voxelization", SIBGRAPI 2012, sec. III-C), written once for every
// SIMD target (cone.cpp). methods/cone_world.cpp derives what it reads from the paper: the prisms of
// a sphere (Poisson-disk points of its great disk and their half chords, III-C1), the chain of
// spheres along each cone (III-C2, with the per-pixel jitter of docs/methods/cone.md) and each
// pixel's point and frame; this kernel places the spheres, tests them against the grid's window
// masks (empty-space skipping), counts their prisms' solid voxels with masks and popcount (Fig. 7)
// and combines the spheres front to back (Fig. 8).
#pragma once

#include <cstdint>

#include "ao/core/gbuffer.h"
#include "ao/core/image.h"
#include "ao/core/math.h"
#include "ao/methods/cone/voxelize.h"

namespace ao::simd {

/// The largest tables the kernel takes (ConeParams' ranges: 64 cones of 16 spheres and the filler,
/// 64 prisms per sphere), in whole vectors.
inline constexpr int kMaxCones = 64, kMaxConePrisms = 64, kMaxConeSlots = 64 * 17;
/// The slots are placed in groups of this many (vectors of 64-bit lanes: 8 on AVX-512, fewer elsewhere).
inline constexpr int kConeSlotGroup = 8;

/// The tables of one call, built once (methods/cone_world.cpp says what each one is).
struct ConeTables {
  // Prisms (sec. III-C1): `prisms` points (u, v) of the unit great disk, arrays padded to
  // `prism_lanes` with zeros; per sphere k of the chain, its radii in voxels along the grid's axes,
  // the sum of its prisms' chords (voxels), and each prism's half chord in voxels at [k * prism_lanes + s].
  int prisms = 0, prism_lanes = 0;
  const float* disk_u = nullptr;
  const float* disk_v = nullptr;
  const float* sphere_rx = nullptr;
  const float* sphere_ry = nullptr;
  const float* sphere_rz = nullptr;
  const float* sphere_chord = nullptr;
  const float* half_chord = nullptr;
  // Slots: the spheres of all cones of a pixel in one flat run, slot i = c * per_cone + j (cone c,
  // lane j of the chain: spheres, then the filler), `slots` of them, a multiple of kConeSlotGroup,
  // padded with never-sampled ones.
  // Per slot, affine in the cone's chain scale s: distance along the axis dist_a s + dist_b
  // (voxels along the axis' unit), radius scale min(rad_a s + rad_b, 1), sampled when
  // use_a s + use_b >= 0; the half extents of its prisms' box at radius scale 1 (x, y in window
  // cells, z in voxels, margins included); the sphere of the chain whose prisms it samples.
  int cones = 0, per_cone = 0, slots = 0;
  const std::int32_t* slot_cone = nullptr;
  const std::int32_t* slot_sphere = nullptr;
  const float* dist_a = nullptr;
  const float* dist_b = nullptr;
  const float* rad_a = nullptr;
  const float* rad_b = nullptr;
  const float* use_a = nullptr;
  const float* use_b = nullptr;
  const float* box_x = nullptr;
  const float* box_y = nullptr;
  const float* box_z = nullptr;
  // The pixel pattern (ConePattern): per pattern slot p, the turn (cos, sin) of the prism pattern
  // at rot[2p], rot[2p + 1], and per cone its axis in the normal's frame and its chain scale at
  // [p * cones_padded + c] (cones_padded = cones rounded up to 16, zeros beyond).
  int cones_padded = 0;
  const float* turn = nullptr;
  const float* axis_x = nullptr;
  const float* axis_y = nullptr;
  const float* axis_z = nullptr;
  const float* axis_scale = nullptr;
  Vec3 inv_voxel;  ///< 1 / voxel size along the grid's (i, j, k) = world (x, z, y).
};

/// How the G-buffer's pixels meet the grid: camera space to world, the grid's origin, and the
/// per-pixel pattern.
struct ConeView {
  Frame basis;           ///< Camera axes in world space (Camera::basis()).
  Vec3 eye;              ///< Camera position, world.
  Vec3 grid_origin;      ///< World point of voxel coordinate (0, 0, 0) (VoxelGrid::origin).
  int pattern_period = 1;  ///< ConePattern::period: pixel (x, y) takes pattern slot (y mod P) P + x mod P.
};

/// V of the covered pixels of the tile [x0, x1) x [y0, y1) of `gb` into `out` (1 on the others):
/// per pixel, its point in the grid and its frame from the G-buffer (world: x, y, z are the grid's
/// i, k, j), then the mean over the cones of the transmittance T after the cone's spheres, front to
/// back, T *= 1 - f (f: a sphere's obstructed fraction, the solid length of its prisms over their
/// chords; spheres the window masks show empty have f = 0; a cone stops at T <= 1e-4), clamped to
/// [0, 1].
void trace_cones(const GBuffer& gb, const VoxelGrid& grid, const ConeTables& tables, const ConeView& view, int x0, int x1, int y0, int y1,
                 ImageView<float> out);

}  // namespace ao::simd
