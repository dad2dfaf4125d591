// SPDX-License-Identifier: Apache-2.0
// The voxelizer's raster stage (methods/voxelize.cpp, step 2), compiled once per SIMD target
// (raster.cpp): its scalar edge tests and depth arithmetic are the voxelizer's hottest loop, and a
// build for baseline x86-64 would otherwise run them without the FMA and three-operand AVX
// instructions the CPU has.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "ao/methods/cone/voxel_raster_internal.h"
#include "ao/methods/cone/voxelize.h"

namespace ao::simd {

/// Rasterises triangles tris[index[0..n)] over the grid's rows [r0, r1] (each clamped to its own
/// rows): parity fragments toggle one bit, slab fragments of open meshes set the voxels within
/// `slab` world units behind them, the fragments of fans (fill >= 3) and of prisms (fill 2) are
/// listed in `hits` and counted in `prisms` (the band's, rows from r0). `perspective`: the eye grid
/// (the depth attribute is 1/z). Returns the fragments.
std::size_t rasterise_triangles(const voxel_internal::GridTri* tris, const std::uint32_t* index, std::size_t n, bool perspective, int r0, int r1,
                                VoxelGrid& g, float slab, std::vector<voxel_internal::ColumnHit>& hits, voxel_internal::PrismCounts* prisms);

}  // namespace ao::simd
