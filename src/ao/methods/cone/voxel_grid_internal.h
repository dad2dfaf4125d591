// SPDX-License-Identifier: Apache-2.0
// The last stages of the voxelizer on a grid whose column bits hold the fragments' toggles
// (voxelize.cpp), and its coarse occupancy for empty-space skipping (voxelize.h). Not installed.
#pragma once

#include <cstddef>

#include "ao/methods/cone/voxelize.h"

namespace ao::voxel_internal {

// Prefix XOR along every column: bit k becomes the XOR of toggles 0..k. Returns the number of
// columns that end odd (open or leaky geometry).
std::size_t scan_columns(VoxelGrid& g);

// Sets the grid's coarse occupancy (blocks, cells and their windowed masks: VoxelGrid) from its
// bits. Returns the number of solid voxels.
std::size_t build_coarse(VoxelGrid& g);

}  // namespace ao::voxel_internal
