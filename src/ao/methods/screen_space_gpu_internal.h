// SPDX-License-Identifier: Apache-2.0
// What the screen-space methods' GPU runs share (containment_gpu.cpp, volumetric_gpu.cpp,
// transfer_gpu.cpp), not installed: the uniforms of their sampling, containment's test offsets as
// a buffer, and the filter after an interleaved pass.
#pragma once

#include <cstdint>
#include <string_view>

#include "ao/core/membership.h"
#include "ao/gpu/run_internal.h"
#include "ao/methods/depth_layers.h"
#include "ao/methods/filters/interleave.h"

namespace ao::gpu_detail {

/// One layer's sheets (depth_layers.h `thickness`, screen_space.glsl): the shaders compile their
/// sheet test only with AO_SHEETS defined (this define when `layers` asks for them, else none), so
/// that without it they stay as small as before.
std::string_view sheets_define(const DepthLayers& layers);
/// With sheets: u_thickness and the sheet test's tolerance in world units, as the CPU kernels take
/// them (screen_space_kernel_internal.h).
void set_sheets(Run& r, Program& p, const DepthLayers& layers);

/// The uniforms containment, transfer and volumetric share: the depth-test bias, the 4x4
/// rotations, the sample count and the silhouette elimination's limit (AT 4.3: a surface more than
/// R in front of the test point, or of the pipe's entry, does not occlude it).
void set_sampling(Run& r, Program& p, int samples, float bias, bool silhouette_elimination, float radius, const InterleaveOptions& interleave,
                  std::uint32_t seed);
/// The containment-test offsets (X, Y, Z, r) of make_containment_samples, as vec4s.
Buffer containment_offsets(Run& r, int n, const Falloff& falloff);
/// `raw` through the box filter when the options ask for it (interleaving and filtering on).
Texture filtered(Run& r, Texture raw, int channels, const InterleaveOptions& o, float radius);

}  // namespace ao::gpu_detail
