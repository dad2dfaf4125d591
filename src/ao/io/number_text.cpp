// SPDX-License-Identifier: Apache-2.0
#include "ao/io/number_text.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <cstdlib>
#include <string>
#include <system_error>

namespace ao {

bool parse_real(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);  // from_chars rejects it; some writers emit it
  if (token.empty()) return false;
  const char* first = token.data();
  const char* last = first + token.size();
  const auto [ptr, ec] = std::from_chars(first, last, value);
  if (ptr != last) return false;
  if (ec == std::errc()) return true;
  if (ec != std::errc::result_out_of_range) return false;
  // Out of double's range: strtod says which way (HUGE_VAL or 0), on the whole token.
  const std::string copy(token);
  value = std::strtod(copy.c_str(), nullptr);
  return true;
}

float narrow_to_float(double d) {
  // IEEE rounding makes anything from FLT_MAX plus half its last place (2^128 - 2^103) on infinite.
  constexpr double kFloatOverflow = 3.4028235677973366e38;  // 2^128 - 2^103
  if (std::abs(d) >= kFloatOverflow) return d > 0 ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
  return static_cast<float>(d);
}

bool parse_real(std::string_view token, float& value) {
  double d = 0;
  if (!parse_real(token, d)) return false;
  value = narrow_to_float(d);
  return true;
}

}  // namespace ao
