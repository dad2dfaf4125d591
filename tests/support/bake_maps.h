// SPDX-License-Identifier: Apache-2.0
// Reading baked maps in tests.
#pragma once

#include <cstddef>

#include "ao/bake/bake_result.h"

namespace ao::test {

/// The mean of `values` (a map of r's size) over r's covered texels; 0 when none is covered.
template <class Map>
double mean_covered(const BakeResult& r, const Map& values) {
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < r.mask.size(); ++i)
    if (r.mask[i]) {
      sum += values[i];
      ++n;
    }
  return n ? sum / static_cast<double>(n) : 0.0;
}

/// The mean of r's map over its covered texels; 0 when none is covered.
inline double mean_covered(const BakeResult& r) { return mean_covered(r, r.visibility); }

}  // namespace ao::test
