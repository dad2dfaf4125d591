// SPDX-License-Identifier: Apache-2.0
// The methods on the GPU: each method's OpenGL compute shaders (in its folder, methods/<name>/;
// installed to share/ao/shaders/; docs/gpu.md), run on a GpuGBuffer with the CPU methods' parameter
// structs, sample sets and rotations, returning what run_method returns (registry.h) plus the GPU
// time of each pass. Which methods have a GPU path is their row's MethodInfo::gpu.
//
//   ao::GpuDevice device = ao::GpuDevice::open();                      // headless (EGL)
//   const ao::GpuGBuffer g = ao::GpuGBuffer::upload(device, gbuffer);  // or rasterize a GpuScene
//   const ao::MethodParams p = ao::find_method("volumetric").decode({});
//   const ao::GpuMethodOutput out = ao::run_gpu_method(device, {g, nullptr, falloff, 1}, p);
//   // out.output.visibility as the CPU method's; out.passes: [{"volumetric", ms}, {"filter", ms}]
#pragma once

#include "ao/gpu/device.h"
#include "ao/gpu/gbuffer.h"
#include "ao/methods/method.h"
#include "ao/registry/registry.h"

namespace ao {

/// Runs the method of `params` on the GPU (check_gpu_method first: InputError, one line, for a
/// method without a GPU path or parameters it does not implement; cone's open-mesh handling on a
/// scene with open or holed meshes is checked when it runs: use "open_meshes": "parity", the
/// paper's voxelization). SystemError for device failures (out of GPU memory), and in a library
/// built without the backend. The output agrees with the CPU method's on the same G-buffer up to
/// float rounding (tests/gpu: tolerances and why).
GpuMethodOutput run_gpu_method(GpuDevice& device, const GpuMethodInput& input, const MethodParams& params);

/// The same from the CPU's inputs (MethodInput): the G-buffer is uploaded (its "upload" pass is
/// listed first) and, for a method that needs the scene, the scene of `input.scene` (or
/// `input.rays`). For one call; a caller that renders frame after frame keeps a GpuGBuffer and
/// GpuScene instead.
GpuMethodOutput run_gpu_method(GpuDevice& device, const MethodInput& input, const MethodParams& params);

}  // namespace ao
