// SPDX-License-Identifier: Apache-2.0
// ao params: a method's or a baker's parameter table as Markdown (the tables in docs/ come from it).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "ao/core/error.h"
#include "ao/core/params.h"
#include "ao/io/atomic_file.h"
#include "ao/registry/registry.h"
#include "subcommands.h"

namespace ao::cli {

void add_params_command(CLI::App& app, const GlobalOptions& global, std::function<int()>& action) {
  auto name = std::make_shared<std::string>();
  auto dir = std::make_shared<std::string>();
  std::string names;
  for (const ParamTableInfo& t : all_param_tables()) names += (names.empty() ? "" : ", ") + std::string(t.name);
  CLI::App* cmd = app.add_subcommand("params", "Print a method's or a baker's parameters (name, valid values, default, meaning) as a Markdown table");
  CLI::Option* one = cmd->add_option("NAME", *name, "A method or a baker: " + names);
  CLI::Option* all = cmd->add_option("--all", *dir, "Write every table as DIR/NAME.md instead (the build's docs/params)");
  one->excludes(all);
  cmd->callback([&action, &global, name, dir] {
    action = [name, dir, &global] {
      if (dir->empty() == name->empty()) throw InputError("ao params: give a NAME, or --all DIR");
      if (global.request_only) return 0;
      if (!name->empty()) {
        std::fputs(params_markdown(find_param_table(*name).specs()).c_str(), stdout);
        return 0;
      }
      for (const ParamTableInfo& t : all_param_tables()) {
        const std::filesystem::path path = std::filesystem::path(*dir) / (std::string(t.name) + ".md");
        write_bytes_atomically(path, params_markdown(t.schema().specs()));
      }
      return 0;
    };
  });
}

}  // namespace ao::cli
