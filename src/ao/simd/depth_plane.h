// SPDX-License-Identifier: Apache-2.0
// The G-buffer's depth as one contiguous plane, built by a SIMD kernel (depth_kernel.cpp):
// the form every kernel that gathers depths reads (the screen-space methods, their filters).
#pragma once

#include "ao/core/gbuffer.h"
#include "ao/core/image.h"

namespace ao {

/// GBuffer::depth of every pixel as one contiguous image (width x height, reusing `out`'s storage):
/// -P.z where covered, +infinity elsewhere. Computed in parallel.
void depth_plane(const GBuffer& g, Image<float>& out);
/// The same as a new image.
Image<float> depth_plane(const GBuffer& g);

}  // namespace ao
