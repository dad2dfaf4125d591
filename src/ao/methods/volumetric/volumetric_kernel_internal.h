// SPDX-License-Identifier: Apache-2.0
// Volumetric AO's kernel (volumetric_kernel.cpp), compiled once per SIMD target; volumetric.cpp
// derives its disk samples from the paper and hands them over.
#pragma once

#include <cstddef>
#include <cstdint>

#include "ao/methods/screen_space_kernel_internal.h"

namespace ao::simd {

/// Volumetric AO's pipes (VAO eq. 6-7, fig. 4 and 7): free[k] = sum over the n disk samples
/// (R/2)(x_i, y_i) rotated by the pixel's angle of the pipe's free length clamp(z* - z_entry, 0,
/// chord) inside the tangent sphere of radius R/2 centred at x + N R/2, chord = R h_i; a pipe whose
/// surface lies more than -far_limit in front of its entry is free (AT 4.3 for pipes). `free`
/// holds padded(row.count) floats.
void sum_free_pipes(const CoveredPixels& row, const DepthPlane& plane, float half_radius, const TestPoints& disk, float far_limit,
                    float* free);

}  // namespace ao::simd
