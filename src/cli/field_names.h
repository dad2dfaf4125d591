// SPDX-License-Identifier: Apache-2.0
// The command line's names of the request fields the job layer's errors name (jobs/fields.h): an
// error "BakeRequest::padding must be in [0, 1024] texels" reads "--padding must be ..." here.
#pragma once

#include <string>
#include <string_view>

namespace ao::cli {

/// The option (or argument) that sets `field`; empty for a field the table lacks.
std::string option_name(std::string_view field);

/// `text` with its marked fields (core/error.h) named by their options.
std::string in_option_words(const std::string& text);

}  // namespace ao::cli
