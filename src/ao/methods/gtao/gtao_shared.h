// SPDX-License-Identifier: Apache-2.0
// What GTAO's CPU kernel (gtao_kernel.cpp, gtao.cpp) and GPU shaders (gtao.comp, gtao_bounce.comp)
// agree on, typed once for both compilers (core/shared.h).
#ifndef AO_METHODS_GTAO_GTAO_SHARED_H_
#define AO_METHODS_GTAO_GTAO_SHARED_H_
#include "ao/core/shared.h"
AO_SHARED_BEGIN

/// acos on [0, 1] by Abramowitz & Stegun 4.4.46: acos(a) ~ sqrt(1 - a) p(a), p(a) = sum_k c_k a^k
/// with c_7 .. c_0 below (|error| <= 2.2e-8 rad, below float resolution near pi/2), evaluated by
/// Horner's scheme from c_7.
AO_CONST float kAcosFit7 = -0.0012624911f;
AO_CONST float kAcosFit6 = 0.0066700901f;
AO_CONST float kAcosFit5 = -0.0170881256f;
AO_CONST float kAcosFit4 = 0.0308918810f;
AO_CONST float kAcosFit3 = -0.0501743046f;
AO_CONST float kAcosFit2 = 0.0889789874f;
AO_CONST float kAcosFit1 = -0.2145988016f;
AO_CONST float kAcosFit0 = 1.5707963050f;

/// Jimenez et al. 2016, sec. 5: the cubic fit of path-traced multi-bounce AO against single-bounce
/// V for surfaces of albedo rho, V' = max(V, ((a V + b) V + c) V) with a = 2.0404 rho - 0.3324,
/// b = -4.7951 rho + 0.6417, c = 2.7552 rho + 0.6903 (max as std::max and GLSL's max: V unless V < the fit).
AO_FN float multi_bounce_fit(float v, float rho) {
  const float a = 2.0404f * rho - 0.3324f;
  const float b = -4.7951f * rho + 0.6417f;
  const float c = 2.7552f * rho + 0.6903f;
  const float fit = ((a * v + b) * v + c) * v;
  return v < fit ? fit : v;
}

AO_SHARED_END
#endif  // AO_METHODS_GTAO_GTAO_SHARED_H_
