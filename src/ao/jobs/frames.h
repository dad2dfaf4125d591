// SPDX-License-Identifier: Apache-2.0
// One scene rendered frame after frame, as a viewer (or a script rendering many views) does: the
// G-buffer of each camera, then a method on it, keeping what methods cache between frames (cone's
// voxel grid, transfer's scratch images) and reusing the G-buffer's storage while nobody else holds
// it. The same G-buffer and method calls as run_render, without the files. The method runs on the
// CPU or, with set_device, on the GPU backend (the G-buffer uploaded each time the method runs).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/camera.h"
#include "ao/core/gbuffer.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/gpu/gbuffer.h"
#include "ao/jobs/device.h"
#include "ao/jobs/inputs.h"
#include "ao/registry/registry.h"

namespace ao {

class FrameRenderer {
 public:
  explicit FrameRenderer(PreparedScene scene);

  const PreparedScene& scene() const { return scene_; }

  /// Renders the G-buffer of `camera` (validated): into the storage of the previous one when no
  /// one else holds it (shared_gbuffer), so a moving camera touches no fresh pages; else into a new one.
  const GBuffer& render_gbuffer(const Camera& camera, const GBufferOptions& options = {}, const ProgressFn& progress = {});
  /// The last G-buffer rendered; null before the first.
  const GBuffer* gbuffer() const { return gbuffer_.get(); }
  /// The last G-buffer, shared with a consumer that outlives the frame (a progressive reference);
  /// the next render_gbuffer then makes a new one unless the consumer has let go.
  std::shared_ptr<const GBuffer> shared_gbuffer() const { return gbuffer_; }

  /// The method of `params` on the last G-buffer, with the cache of this scene. On the GPU:
  /// run_gpu_method on the G-buffer uploaded (InputError, one line, for what the GPU backend does
  /// not run), the scene uploaded when a method that needs it first runs; gpu_passes() then has
  /// its times.
  MethodOutput run(const MethodParams& params, const Falloff& falloff, std::uint32_t seed, const ProgressFn& progress = {});

  /// Where run() computes: the CPU (default, `gpu` ignored), or the GPU backend on `gpu`, which
  /// must outlive this renderer's runs on it (a viewer's window context, GpuDevice::from_current_context).
  void set_device(Device device, GpuDevice* gpu = nullptr);
  Device device() const { return device_; }
  /// GPU time of each pass of the last run() on the GPU, in the order they ran: "upload" (the
  /// G-buffer), then the method's; empty after a run on the CPU.
  const std::vector<GpuPassTime>& gpu_passes() const { return gpu_passes_; }

 private:
  MethodOutput run_on_gpu(const MethodParams& params, const Falloff& falloff, std::uint32_t seed);

  PreparedScene scene_;
  std::shared_ptr<GBuffer> gbuffer_;
  MethodCache cache_;
  Device device_ = Device::Cpu;
  GpuDevice* gpu_ = nullptr;
  std::optional<GpuScene> gpu_scene_;  ///< Uploaded when a method that needs the scene (cone) first runs on the GPU; keeps its grid between runs.
  std::vector<GpuPassTime> gpu_passes_;
};

}  // namespace ao
