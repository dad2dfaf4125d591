// SPDX-License-Identifier: Apache-2.0
// What `ao` says when its command line cannot be parsed: one line in ao's words, prefixed
// "ao: error:", naming the command, with the closest known name for a mistyped command or option.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace CLI {
class App;
class ParseError;
}  // namespace CLI

namespace ao::cli {

/// Prints the one-line message for `e` (thrown by app.parse on argv) and returns the exit code:
/// 0 for --help and --version (printed as CLI11 does), 1 for a bad value, 2 for bad usage.
int report_parse_error(CLI::App& app, const CLI::ParseError& e, int argc, char** argv);

}  // namespace ao::cli
