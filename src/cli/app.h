// SPDX-License-Identifier: Apache-2.0
// The ao command line as one CLI11 app: the global options and every subcommand. main.cpp parses
// argv with it and runs the chosen command; the option parser's fuzzing harness
// (fuzz/fuzz_options.cpp) parses its inputs with the same app.
#pragma once

#include <functional>

#include <CLI/CLI.hpp>

#include "common.h"

namespace ao::cli {

/// Adds --version, --threads, --quiet and every subcommand to `app` (made with ao's description
/// and name, "ao"). Once app.parse succeeds, `action` holds the chosen command's work.
void add_ao_commands(CLI::App& app, GlobalOptions& global, std::function<int()>& action);

}  // namespace ao::cli
