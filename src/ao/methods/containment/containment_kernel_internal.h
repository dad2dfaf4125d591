// SPDX-License-Identifier: Apache-2.0
// Containment AO's kernel (containment_kernel.cpp), compiled once per SIMD target; containment.cpp
// derives its samples from the papers and hands them over.
#pragma once

#include <cstddef>
#include <cstdint>

#include "ao/methods/screen_space_kernel_internal.h"

namespace ao::simd {

/// Containment AO (VAO eq. 5; AT sec. 4 with m tests per ray): open[k] = the number of the n rays
/// of entry k all of whose m test points x + (j/m)(X T + Y B + Z N), j = 1..m, are free: depth
/// distance z* - depth(p) >= -bias, or (AT sec. 4.3) at most `far_limit` (< 0; -infinity: no
/// elimination), or p behind the camera. `open` holds padded(row.count) floats.
void count_open_rays(const CoveredPixels& row, const DepthPlane& plane, const TestPoints& samples, int m, float far_limit, float* open);

}  // namespace ao::simd
