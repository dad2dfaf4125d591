// SPDX-License-Identifier: Apache-2.0
// run_gpu_method in a library built without the GPU backend (AO_GPU=OFF): there is no device to
// run on (gpu/device_nogpu.cpp refuses to open one).
#include "ao/gpu/nogpu_internal.h"
#include "ao/registry/methods_gpu.h"

namespace ao {

GpuMethodOutput run_gpu_method(GpuDevice&, const GpuMethodInput&, const MethodParams&) { gpu_detail::unavailable(); }
GpuMethodOutput run_gpu_method(GpuDevice&, const MethodInput&, const MethodParams&) { gpu_detail::unavailable(); }

}  // namespace ao
