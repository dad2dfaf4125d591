// SPDX-License-Identifier: Apache-2.0
// Which backend computes a job's AO: the CPU kernels (src/ao/methods/, the default) or the GPU
// backend's compute shaders (src/ao/gpu/, docs/gpu.md). The requests carry the choice (RenderRequest,
// CompareSettings, FrameRenderer); the ray-traced reference, the G-buffer of `ao render` and
// `ao compare` and everything else stay on the CPU.
#pragma once

#include <span>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "ao/gpu/device.h"

namespace ao {

/// Where a method runs.
enum class Device {
  Cpu,  ///< The CPU kernels (the registry's run functions).
  Gpu,  ///< The GPU backend (run_gpu_method): OpenGL 4.3 compute shaders, on the G-buffer the job made.
};

/// "cpu" or "gpu".
const char* to_string(Device device);
/// The device called `name` ("cpu" or "gpu"); InputError "--device: cpu or gpu, got 'x'" otherwise.
Device device_from_name(const std::string& name);

/// The GPU passes as people read them, in the order they ran: "upload 0.41 ms, volumetric 32.6 ms,
/// filter 25.4 ms" (three significant digits).
std::string describe_gpu_passes(std::span<const GpuPassTime> passes);
/// The GPU passes as JSON, in the order they ran: [{"name": "upload", "ms": 0.41}, ...].
nlohmann::json gpu_passes_json(std::span<const GpuPassTime> passes);

}  // namespace ao
