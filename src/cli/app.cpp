// SPDX-License-Identifier: Apache-2.0
#include "app.h"

#include "ao/simd/target.h"
#include "ao/version.h"
#include "subcommands.h"

namespace ao::cli {

void add_ao_commands(CLI::App& app, GlobalOptions& global, std::function<int()>& action) {
  app.set_version_flag("--version", [] { return "ao " AO_VERSION_STRING " (SIMD: " + ao::simd_target() + ")"; });
  app.require_subcommand(1);
  app.fallthrough();  // --threads and --quiet may also follow the subcommand
  app.add_option("--threads", global.threads, "Worker threads (default: all cores)")->check(CLI::Range(0, 1024));
  app.add_flag("-q,--quiet", global.quiet, "No progress output (bar or log lines)");
  add_render_command(app, global, action);
  add_bake_command(app, global, action);
  add_compare_command(app, global, action);
  add_params_command(app, global, action);
  add_view_command(app, global, action);
  add_tune_command(app, global, action);
}

}  // namespace ao::cli
