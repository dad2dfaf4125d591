// SPDX-License-Identifier: Apache-2.0
// Rec. 709 luminance, the scalar value of an RGB result (ambient transfer's W, GTAO's multi-bounce
// albedo, the reference's transfer), read by C++ and by the GPU shaders alike (core/shared.h).
#ifndef AO_CORE_COLOR_SHARED_H_
#define AO_CORE_COLOR_SHARED_H_
#include "ao/core/shared.h"
AO_SHARED_BEGIN

/// Rec. 709 (sRGB primaries) luminance weights of linear R, G and B.
AO_CONST float kLuminanceR = 0.2126f;
AO_CONST float kLuminanceG = 0.7152f;
AO_CONST float kLuminanceB = 0.0722f;
/// kLuminanceR r + kLuminanceG g + kLuminanceB b, summed in that order.
AO_FN float luminance(float r, float g, float b) { return kLuminanceR * r + kLuminanceG * g + kLuminanceB * b; }

AO_SHARED_END
#endif  // AO_CORE_COLOR_SHARED_H_
