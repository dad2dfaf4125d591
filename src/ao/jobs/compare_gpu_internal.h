// SPDX-License-Identifier: Apache-2.0
// The GPU backend's column of a comparison (CompareSettings::device gpu, compare.h): the G-buffer
// uploaded once, the scene for cone, each method run on the device and judged as its CPU row is.
// Not installed.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "ao/core/image.h"
#include "ao/core/membership.h"
#include "ao/gpu/gbuffer.h"
#include "ao/jobs/compare.h"
#include "ao/registry/registry.h"

namespace ao {

class CompareGpuColumn {
 public:
  /// Uploads `gbuffer` to `device`, or to a headless device opened here when `device` is null
  /// (SystemError without a usable OpenGL 4.3). `scene` (cone voxelizes it) must outlive this.
  CompareGpuColumn(GpuDevice* device, const RayScene& scene, const GBuffer& gbuffer);

  const std::string& renderer() const { return device_.renderer(); }
  /// GPU time of the G-buffer's upload.
  double upload_ms() const;

  /// The method of `params` on the GPU, judged against `reference` over `covered` and
  /// measured against the CPU's V `cpu`. What the GPU backend does not run (an InputError: a CPU
  /// only method, a characteristic function, cone's open-mesh modes) comes back as `skipped`.
  /// `keep_images`: keep V and the heat map (the table's rows; a sweep needs only the numbers).
  CompareGpuRun run(const MethodParams& params, const Falloff& falloff, std::uint32_t seed,
                    const Image<float>& reference, const Image<float>& cpu, const Image<std::uint8_t>& covered, bool keep_images);

 private:
  std::optional<GpuDevice> own_;
  GpuDevice& device_;
  const RayScene& scene_;
  GpuGBuffer gbuffer_;
  std::optional<GpuScene> gpu_scene_;  ///< Uploaded when a method that needs the scene (cone) first runs.
};

/// A row's "gpu" object in table.json (compare_table_json).
nlohmann::json gpu_run_json(const CompareGpuRun& run);

/// What table.md says below its table with the GPU backend: the renderer, what "ms gpu" and the
/// GPU passes are, the methods the GPU did not run and why, and sheet.png's columns.
std::string gpu_markdown_notes(const CompareResult& result);

}  // namespace ao
