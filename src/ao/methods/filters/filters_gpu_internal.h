// SPDX-License-Identifier: Apache-2.0
// The methods' filters on the GPU (filters_gpu.cpp), not installed: the 4x4 depth-aware box filter
// of interleaved sampling and the separable cross-bilateral filter, as their CPU versions compute them.
#pragma once

#include <array>
#include <string>

#include "ao/gpu/run_internal.h"
#include "ao/methods/filters/bilateral.h"
#include "ao/methods/filters/interleave.h"

namespace ao::gpu_detail {

/// The 16 (cos, sin) of interleave_rotations as the shaders' u_rotation[16].
void set_rotations(Run& r, Program& p, const std::array<Rotation, 16>& rotations);
/// box_filter.comp over `values` (CHANNELS 1: R32F; 4: RGBA32F) as the pass "filter".
Texture box_filter(Run& r, const Texture& values, int channels, float depth_limit);
/// bilateral.comp's two passes over the R32F `values` (bilateral.h), as the pass `name`.
Texture bilateral_filter(Run& r, const Texture& values, const BilateralParams& params, const std::string& name);

}  // namespace ao::gpu_detail
