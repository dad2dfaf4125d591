// SPDX-License-Identifier: Apache-2.0
// The SIMD kernels' instruction sets (the *_kernel.cpp files: simd/ and each owner's folder): every kernel is compiled
// once per x86-64 target (Highway's: AVX3_DL (Ice Lake, Zen 4) and AVX3 (Skylake-X), the AVX-512
// variants; AVX2 (Haswell, Zen); SSE4 (with AES and CLMUL: Westmere); SSSE3 (Core 2, Nehalem); the
// portable fallback without SIMD instructions: EMU128, or SCALAR when the compiler is GCC before
// 12.3, whose EMU128 code Highway 1.0 does not trust) and the best one the CPU runs is chosen when a
// kernel is first called. A build with AO_NATIVE=ON has only the target of its own machine.
//
// Agreement of the targets: the kernels compute the same operations in the same order on every
// target (sums over lanes run in lane order; fused multiply-adds only where the kernel says so), so
// the targets with FMA (AVX3_DL, AVX3, AVX2) give the same bits. SSE4, SSSE3 and the fallback
// have no fused multiply-add and round its product first, which moves a test point by about an ulp: a
// depth or voxel test decided within that distance can flip (tests/methods/simd_targets_test.cpp
// states the tolerance).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace ao {

/// Name of the target the kernels run with in this process: "AVX3_DL", "AVX3", "AVX2", "SSE4",
/// "SSSE3", "EMU128" or "SCALAR" (Highway's names). The best of simd_targets() unless set_simd_target chose another.
std::string simd_target();

/// The targets this build has kernels for and this CPU can run, best first.
std::vector<std::string> simd_targets();

/// Makes the kernels run with target `name` (one of simd_targets()) from the next call on; ""
/// returns to the best. For tests and measurements that compare targets on one machine: it applies
/// to the whole process, so call it while no kernel runs. InputError for a name not in simd_targets().
void set_simd_target(std::string_view name);

}  // namespace ao
