// SPDX-License-Identifier: Apache-2.0
#include "ao/simd/target.h"

#include <cstdint>

#include <hwy/highway.h>
#include <hwy/targets.h>

#include "ao/core/closest_name.h"
#include "ao/core/error.h"

namespace ao {

namespace {
// HWY_TARGETS here equals the kernels' (the same compile definitions apply to the whole library).
std::int64_t available() { return hwy::SupportedTargets() & HWY_TARGETS; }
}  // namespace

std::string simd_target() {
  const std::int64_t t = available();
  return hwy::TargetName(t & -t);  // the lowest bit is the best target
}

std::vector<std::string> simd_targets() {
  // Unaffected by a set_simd_target in force: what the CPU and the build offer.
  std::vector<std::string> names;
  const std::int64_t chosen = hwy::SupportedTargets();
  hwy::SetSupportedTargetsForTest(0);
  for (std::int64_t t = available(); t != 0; t &= t - 1) names.emplace_back(hwy::TargetName(t & -t));
  if (chosen != hwy::SupportedTargets()) hwy::SetSupportedTargetsForTest(chosen);
  return names;
}

void set_simd_target(std::string_view name) {
  hwy::SetSupportedTargetsForTest(0);
  if (name.empty()) return;
  std::string known;
  for (std::int64_t t = available(); t != 0; t &= t - 1) {
    const std::int64_t one = t & -t;
    if (name == hwy::TargetName(one)) {
      hwy::SetSupportedTargetsForTest(one);
      return;
    }
    known += (known.empty() ? "" : ", ") + std::string(hwy::TargetName(one));
  }
  throw InputError("SIMD target '" + std::string(name) + "' is not one this build and CPU run (" + known + ")" + did_you_mean(name, known));
}

}  // namespace ao
