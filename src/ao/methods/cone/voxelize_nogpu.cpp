// SPDX-License-Identifier: Apache-2.0
// gpu_voxelize_world in a library built without the GPU backend (AO_GPU=OFF): there is no device.
#include "ao/gpu/nogpu_internal.h"
#include "ao/methods/cone/voxelize_gpu.h"

namespace ao {

VoxelGrid gpu_voxelize_world(GpuDevice&, const GpuScene&, const VoxelizeOptions&, VoxelStats*) { gpu_detail::unavailable(); }

}  // namespace ao
