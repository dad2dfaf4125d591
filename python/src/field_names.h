// SPDX-License-Identifier: Apache-2.0
// The Python module's names of the request fields the job layer's errors name (jobs/fields.h):
// an error "BakeRequest::padding must be in [0, 1024] texels" reads "padding must be ..." here,
// the keyword argument of ao.bake that sets it.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace ao::python {

/// The keyword argument (or argument.field) that sets `field`; empty for a field the Python
/// module does not expose, which then keeps its library name.
std::string keyword_name(std::string_view field);

/// Every row of the table, for the test that checks it covers jobs/fields.h.
std::vector<std::pair<std::string, std::string>> keyword_table();

}  // namespace ao::python
