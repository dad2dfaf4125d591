// SPDX-License-Identifier: Apache-2.0
// What Alchemy AO's CPU kernel (alchemy_kernel.cpp) and GPU shader (alchemy.comp) agree on, typed
// once for both compilers (core/shared.h), so both place the same samples.
#ifndef AO_METHODS_ALCHEMY_ALCHEMY_SHARED_H_
#define AO_METHODS_ALCHEMY_ALCHEMY_SHARED_H_
#include "ao/core/shared.h"
AO_SHARED_BEGIN

/// Cap on the disk's screen radius, pixels: a disk covering the image gains nothing from a larger one.
AO_CONST float kAlchemyMaxPixelRadius = 16384.0f;
/// Added to sample coordinates (pixels) before they are truncated to ints and subtracted after, so
/// coordinates stay positive below it (kAlchemyMaxPixelRadius plus the image) and truncation acts as floor.
AO_CONST float kAlchemyCoordOffset = 65536.0f;
/// The reciprocal square root's bit trick (1/sqrt(x) ~ bits(kInvSqrtMagic - (bits(x) >> 1)),
/// refined by two Newton steps to a relative error < 5e-6): sqrt of a unit-disk radius on both backends.
AO_CONST uint kInvSqrtMagic = 0x5f3759dfu;

AO_SHARED_END
#endif  // AO_METHODS_ALCHEMY_ALCHEMY_SHARED_H_
