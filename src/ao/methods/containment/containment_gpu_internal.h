// SPDX-License-Identifier: Apache-2.0
// Containment's GPU path (containment_gpu.cpp: containment.comp), not installed: what the registry's
// run_gpu_method calls for its parameters (methods/method.h).
#pragma once

#include "ao/gpu/run_internal.h"
#include "ao/methods/method.h"
#include "ao/methods/containment/containment.h"

namespace ao::gpu_detail {

/// The method on the device with the CPU kernel's sample sets and rotations; the output as run()'s
/// (up to float rounding: tests/gpu). Parameters are checked by the caller's decode and check_gpu.
MethodOutput run_gpu(Run& r, const GpuMethodInput& in, const ContainmentParams& params);

}  // namespace ao::gpu_detail
