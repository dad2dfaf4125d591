// SPDX-License-Identifier: Apache-2.0
// Runs the test binary with the SIMD kernels restricted to one target: AO_SIMD_TARGET=AVX2 (one of
// ao::simd_targets()) makes every kernel of the run use that target, so one machine tests all the
// targets it has (tests/CMakeLists.txt registers the method, filter and cone tests once per
// target). A target this CPU or build lacks ends the run with exit code 77, which CTest reports as
// skipped (SKIP_RETURN_CODE), saying why; so does the best one: the run without AO_SIMD_TARGET uses
// it. (GoogleTest 1.12 counts the tests of an environment that skips as passed.)
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "ao/simd/target.h"

namespace {

class SimdTargetEnvironment : public ::testing::Environment {
 public:
  void SetUp() override {
    const char* name = std::getenv("AO_SIMD_TARGET");
    if (!name || !*name) return;
    const std::vector<std::string> targets = ao::simd_targets();
    if (!targets.empty() && targets.front() == name) skip(name, "the best target, which the run without AO_SIMD_TARGET tests");
    for (const std::string& t : targets)
      if (t == name) {
        ao::set_simd_target(name);
        return;
      }
    skip(name, "not a target this CPU and build run");
  }

 private:
  [[noreturn]] static void skip(const char* name, const char* why) {
    std::printf("AO_SIMD_TARGET=%s: %s: skipped\n", name, why);
    std::fflush(stdout);
    std::_Exit(kSkipped);
  }
  static constexpr int kSkipped = 77;  // SKIP_RETURN_CODE of these tests (tests/CMakeLists.txt)
};

const ::testing::Environment* const kEnvironment = ::testing::AddGlobalTestEnvironment(new SimdTargetEnvironment);

}  // namespace
