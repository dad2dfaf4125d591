// SPDX-License-Identifier: Apache-2.0
// The floating-point mode of the x86 SSE control register (MXCSR), the one place outside the SIMD
// kernels' sources that speaks to the instruction set: every x86-64 CPU has it, so it needs no
// dispatch.
#pragma once

#include <pmmintrin.h>
#include <xmmintrin.h>

namespace ao::detail {

/// Flush-to-zero and denormals-are-zero for the lifetime of the object, on this thread, restored
/// on destruction. Embree asks for them on every thread that traces (denormal arithmetic in
/// traversal is slow), and a kernel whose float results may underflow (the bake filter's weights)
/// sets them so that its results do not depend on the mode a pool thread was left in: a thread's
/// mode is whatever the last task it ran set, so work that does not set its own would round
/// differently on different threads. Two register writes each way, cheap against a tile of rays.
class FlushDenormalsScope {
 public:
  FlushDenormalsScope() : saved_(_mm_getcsr()) {
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
  }
  ~FlushDenormalsScope() { _mm_setcsr(saved_); }
  FlushDenormalsScope(const FlushDenormalsScope&) = delete;
  FlushDenormalsScope& operator=(const FlushDenormalsScope&) = delete;

 private:
  unsigned saved_;
};

}  // namespace ao::detail
