// SPDX-License-Identifier: Apache-2.0
// What cone tracing's CPU kernel (cone_kernel.cpp, cone.cpp) and GPU shader (cone_trace.comp) agree
// on, typed once for both compilers (core/shared.h).
#ifndef AO_METHODS_CONE_CONE_SHARED_H_
#define AO_METHODS_CONE_CONE_SHARED_H_
#include "ao/core/shared.h"
AO_SHARED_BEGIN

/// A cone stops once its transmittance T <= kConeOpaque: its remaining spheres can lower T by at
/// most kConeOpaque, so V (the mean over cones) by at most 1e-4, far below an 8-bit step (1/255).
AO_CONST float kConeOpaque = 1e-4f;

AO_SHARED_END
#endif  // AO_METHODS_CONE_CONE_SHARED_H_
