// SPDX-License-Identifier: Apache-2.0
// One view of a prepared scene: what run_render (jobs/render.h) does after loading, and what the
// viewer and FrameRenderer (jobs/frames.h) do per frame. Apart from jobs/render.h so that a
// program that only renders does not parse every method's header (the registry's).
#pragma once

#include <cstdint>
#include <optional>

#include <nlohmann/json_fwd.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/membership.h"
#include "ao/core/progress.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/jobs/device.h"
#include "ao/jobs/inputs.h"
#include "ao/jobs/reporter.h"
#include "ao/reference/direct_light.h"
#include "ao/registry/registry.h"

namespace ao {

/// InputError when the method of `params` cannot run on `device`: nothing for the CPU; for the
/// GPU, check_gpu_method (registry.h: what the GPU backend does not run, and the way out, --device
/// cpu). Needs no scene and no device; a library built without the backend says so when the device
/// is opened.
void check_device(Device device, const MethodParams& params);

/// The method's parameters, decoded once: its defaults, then `samples` and `target_error` where
/// the method has them (InputError where it has not), then `overrides`; checked by its table.
/// params_json (registry.h) gives them back complete, for an echo.
MethodParams method_params(const MethodInfo& method, const nlohmann::json& overrides, std::optional<int> samples = {},
                           std::optional<float> target_error = {});

/// The G-buffer channels a render needs: albedo for screen-space methods (and the sun pass, a
/// shaded picture, a G-buffer file), UVs for an AO map.
GBufferOptions gbuffer_options_for(const MethodInfo& method, SurfaceNormal normal, bool albedo_for_outputs, bool uv);

/// The G-buffer of `camera` in `scene`, with the direct-light pass when `sun` is given.
GBuffer render_view_gbuffer(const PreparedScene& scene, const Camera& camera, const GBufferOptions& options, const std::optional<Sun>& sun,
                            const JobReporter& reporter = {});

/// The method of `params` on `gbuffer` (rendered from `scene`, or from a file when `scene` is
/// null). `cache`: null, or what the method keeps between frames of this scene.
MethodOutput run_on_scene(const MethodParams& params, const GBuffer& gbuffer, const PreparedScene* scene, const Falloff& falloff,
                          std::uint32_t seed, MethodCache* cache = nullptr, const ProgressFn& progress = {});

}  // namespace ao
