// SPDX-License-Identifier: Apache-2.0
// The prelude of a header that C++ and GLSL both read (a *_shared.h file: constants and small
// functions the CPU kernels and the GPU shaders must agree on, typed once; the shader loader
// expands `#include`, each file once).
//
// The language is the intersection of C++20 and GLSL 4.30: scalar float, int and uint values,
// literals with an `f` or `u` suffix, arithmetic, ternaries and functional casts (`float(x)`).
// A shared header puts its definitions between AO_SHARED_BEGIN and AO_SHARED_END, each value as
// `AO_CONST float kName = ...;` and each function as `AO_FN float name(...)`. C++ reads them in
// namespace ao::shared (where `uint` is std::uint32_t) as `inline constexpr` values and `constexpr`
// functions; GLSL as `const` values and plain functions.
#ifndef AO_CORE_SHARED_H_
#define AO_CORE_SHARED_H_

#ifdef __cplusplus
#include <cstdint>
#define AO_SHARED_BEGIN \
  namespace ao::shared {  \
  using uint = std::uint32_t;
#define AO_SHARED_END }
#define AO_CONST inline constexpr
#define AO_FN constexpr
#else
#define AO_SHARED_BEGIN
#define AO_SHARED_END
#define AO_CONST const
#define AO_FN
#endif

#endif  // AO_CORE_SHARED_H_
