// SPDX-License-Identifier: Apache-2.0
// The cone method's voxel grid built on the GPU as Dalla Favera & Celes (SIBGRAPI 2012, sec.
// III-B) build it after Eisemann & Decoret (GI 2008): every triangle rasterized into the grid's
// columns, each fragment XOR-ing the depth-slab mask of the voxels beyond it into the column's bits
// (shaders/cone_voxelize.*). It is the CPU's world grid (methods/voxelize.h) bit for bit.
#pragma once

#include "ao/gpu/device.h"
#include "ao/gpu/gbuffer.h"
#include "ao/methods/cone/voxelize.h"

namespace ao {

/// voxelize_world's grid of `scene` built on the GPU and read back: the layout (nx, ny, depth_bits,
/// words, origin, voxel_size) and `bits`, equal to voxelize_world's for the same options (the
/// coarse occupancy masks, which only the CPU kernel reads, are left empty). `stats`, when given,
/// gets the counts voxelize_world reports (triangles, fragments, odd columns, set voxels, and the
/// meshes' closure; triangles stay 0 on a GPU whose geometry stage cannot write storage buffers).
///
/// The GPU rasterizes by parity (the paper's). Where the options ask for another solid (open
/// surfaces thickened into slabs, holed meshes closed by their winding number, closed meshes around
/// the camera taken inside out), the grid is the CPU's voxelize_world, uploaded: either way the
/// grid traced on the GPU is the CPU's, bit for bit.
VoxelGrid gpu_voxelize_world(GpuDevice& device, const GpuScene& scene, const VoxelizeOptions& options, VoxelStats* stats = nullptr);

}  // namespace ao
