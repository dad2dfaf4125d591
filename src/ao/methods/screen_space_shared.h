// SPDX-License-Identifier: Apache-2.0
// What the screen-space methods' CPU kernels (screen_space_kernel.cpp) and GPU shaders
// (gpu/shaders/common.glsl: depth_bias) agree on, typed once for both compilers (core/shared.h).
#ifndef AO_METHODS_SCREEN_SPACE_SHARED_H_
#define AO_METHODS_SCREEN_SPACE_SHARED_H_
#include "ao/core/shared.h"
AO_SHARED_BEGIN

/// The depth-test bias's floor on cos theta_v (theta_v: the angle between the normal and the view
/// ray): cos 82.9 degrees, so tan theta_v <= 8 and a grazing surface's bias stays at most nine pixel
/// footprints at its depth.
AO_CONST float kMinViewCosine = 0.124f;

AO_SHARED_END
#endif  // AO_METHODS_SCREEN_SPACE_SHARED_H_
