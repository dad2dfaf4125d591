// SPDX-License-Identifier: Apache-2.0
// Numbers in text mesh files (OBJ, OFF, ASCII PLY and STL), read the same way in every format:
// a value too small for a float reads as 0 (or a float denormal), as C's strtof and every other
// mesh tool read it; a value too large is infinite, which the loaders refuse as non-finite.
#pragma once

#include <string_view>

namespace ao {

/// Parses `token` (all of it; a leading '+' is allowed) as a decimal or hexadecimal floating-point
/// number, "inf" or "nan". Values beyond double's range read as strtod reads them: +-infinity for
/// an overflow, +-0 for an underflow (1e-400). False when `token` is not a number.
bool parse_real(std::string_view token, double& value);

/// `d` rounded to float as IEEE arithmetic rounds it: +-infinity from FLT_MAX plus half its last
/// place on (a plain cast of such a double is undefined behaviour), NaN stays NaN.
float narrow_to_float(double d);

/// parse_real, then rounded to float: +-infinity beyond float's range, a denormal or +-0 below it
/// (1e-320 reads as 0 in OFF, PLY, STL and OBJ alike).
bool parse_real(std::string_view token, float& value);

}  // namespace ao
