// SPDX-License-Identifier: Apache-2.0
// Wall-clock stopwatch in milliseconds, for the timings jobs report.
#pragma once

#include <chrono>

namespace ao {

class Stopwatch {
 public:
  /// Milliseconds since construction or the previous lap.
  double lap_ms() {
    const auto now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - start_).count();
    start_ = now;
    return ms;
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace ao
