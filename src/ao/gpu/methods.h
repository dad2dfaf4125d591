// The methods on the GPU: containment, volumetric, transfer, alchemy, gtao and cone as OpenGL
// compute shaders (src/ao/gpu/shaders/, installed to share/ao/shaders/; docs/gpu.md), run on a
// GpuGBuffer with the CPU methods' parameter tables, sample sets and rotations, and returning what
// the CPU registry's run functions return (methods/registry.h) plus the GPU time of each pass.
//
//   ao::GpuDevice device = ao::GpuDevice::open();                  // headless (EGL)
//   const ao::GpuGBuffer g = ao::GpuGBuffer::upload(device, gbuffer);  // or rasterize a GpuScene
//   const ao::GpuMethodOutput out = ao::run_gpu_method(device, "volumetric", {g, nullptr, falloff, 1}, params);
//   // out.output.visibility as the CPU method's; out.passes: [{"volumetric", ms}, {"filter", ms}]
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/membership.h"
#include "ao/gpu/device.h"
#include "ao/gpu/gbuffer.h"
#include "ao/registry/registry.h"

namespace ao {

/// What a GPU method reads: the G-buffer on the device, and for cone (which voxelizes the scene)
/// the scene on the same device.
struct GpuMethodInput {
  const GpuGBuffer& gbuffer;
  const GpuScene* scene = nullptr;  ///< cone only; null otherwise.
  Falloff falloff;                  ///< R and membership, as MethodInput::falloff.
  std::uint32_t seed = 0;           ///< Keys the sample rotations and jitter, as MethodInput::seed.
};

/// A GPU method's result.
struct GpuMethodOutput {
  /// As the CPU method returns it (visibility, color, extras: transfer's W and obscurance, alchemy's
  /// unfiltered V, gtao's multi-bounce colour), with `stats` extended by "device" (the GL renderer)
  /// and "gpu_ms" (pass name -> milliseconds).
  MethodOutput output;
  std::vector<GpuPassTime> passes;  ///< GPU time of each pass, in the order they ran.
  std::string renderer;             ///< GL_RENDERER of the device that ran it.
};

/// The methods the GPU backend runs, in the registry's order: containment, volumetric, transfer,
/// cone, alchemy, gtao (not raytraced: the ground truth stays on the CPU).
std::span<const std::string_view> gpu_method_names();

/// The checks of run_gpu_method that need no device, for a caller that wants to refuse a run
/// before loading anything: InputError (one line, naming the way out) when `method` is not one the
/// GPU runs, when `params` (read through its parameter table, with its messages) are not valid, or
/// when they ask for what the backend does not implement (a characteristic function other than the
/// depth buffer, cone's eye grid). What depends on the scene (cone's open meshes) is checked when it
/// runs. In a library built without the backend: SystemError saying so.
void check_gpu_method(std::string_view method, const nlohmann::json& params);

/// Runs `method` on the GPU with `params` read through its parameter table (InputError, one line,
/// for unknown keys, wrong types, values out of range, as the CPU run does). What the GPU backend
/// does not implement is an InputError naming it: a characteristic function other than the depth
/// buffer ("characteristic"), cone's eye grid ("grid": "eye") and cone's open-mesh handling on a
/// scene with open or holed meshes (use "open_meshes": "parity", the paper's voxelization).
/// SystemError for device failures (out of GPU memory). The output agrees with the CPU method's on
/// the same G-buffer up to float rounding (tests/gpu: tolerances and why).
GpuMethodOutput run_gpu_method(GpuDevice& device, std::string_view method, const GpuMethodInput& input, const nlohmann::json& params);

/// The same from the CPU registry's inputs (MethodInput): the G-buffer is uploaded (its "upload"
/// pass is listed first) and, for cone, the scene of `input.scene`. For one call; a caller that
/// renders frame after frame keeps a GpuGBuffer / GpuScene instead.
GpuMethodOutput run_gpu_method(GpuDevice& device, std::string_view method, const MethodInput& input, const nlohmann::json& params);

}  // namespace ao
