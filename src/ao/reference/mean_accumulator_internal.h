// SPDX-License-Identifier: Apache-2.0
// Running sums of one point's (pixel's, texel's) Monte Carlo samples: the mean and its standard
// error, for the references' adaptive stopping and reports and for the bakers' texels. Internal
// to the ray-tracing passes (namespace detail).
#pragma once

#include <algorithm>
#include <cmath>

namespace ao::detail {

/// Sums of samples of a value in [0, 1]; doubles, so that a million samples stay exact enough.
struct MeanAccumulator {
  double sum = 0, sum_sq = 0;
  int n = 0;

  void add(double v) {
    sum += v;
    sum_sq += v * v;
    ++n;
  }
  /// `count` samples at once, whose values sum to `s` and whose squares sum to `s2`.
  void add(int count, double s, double s2) {
    sum += s;
    sum_sq += s2;
    n += count;
  }
  /// The mean; 1 (open) with no samples.
  double mean() const { return n > 0 ? sum / n : 1.0; }
  /// Unbiased sample variance of one sample; 0 below two samples.
  double variance() const { return n < 2 ? 0.0 : std::max(0.0, (sum_sq - sum * sum / n) / (n - 1)); }
  /// Standard error of the mean from the unbiased sample variance (conservative for scrambled
  /// Sobol samples, whose error is usually smaller).
  double std_error() const { return n < 2 ? 0.0 : std::sqrt(variance() / n); }
};

}  // namespace ao::detail
