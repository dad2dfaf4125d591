// SPDX-License-Identifier: Apache-2.0
// Each subcommand registers its options and, when chosen, sets `action` to the work to run.
#pragma once

#include <functional>

#include <CLI/CLI.hpp>

#include "common.h"

namespace ao::cli {

void add_render_command(CLI::App& app, const GlobalOptions& global, std::function<int()>& action);
void add_bake_command(CLI::App& app, const GlobalOptions& global, std::function<int()>& action);
void add_compare_command(CLI::App& app, const GlobalOptions& global, std::function<int()>& action);
void add_params_command(CLI::App& app, const GlobalOptions& global, std::function<int()>& action);
void add_view_command(CLI::App& app, const GlobalOptions& global, std::function<int()>& action);
void add_tune_command(CLI::App& app, const GlobalOptions& global, std::function<int()>& action);

}  // namespace ao::cli
