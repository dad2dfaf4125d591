// ao params: a method's parameter table as Markdown (the tables in docs/methods/ come from it).
#include <cstdio>
#include <string>

#include "ao/core/error.h"
#include "ao/core/params.h"
#include "ao/registry/registry.h"
#include "subcommands.h"

namespace ao::cli {

void add_params_command(CLI::App& app, const GlobalOptions&, std::function<int()>& action) {
  auto method = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("params", "Print a method's parameters (name, valid values, default, meaning) as a Markdown table");
  cmd->add_option("METHOD", *method, "The method (ao render --help lists them)")->required();
  cmd->callback([&action, method] {
    action = [method] {
      const MethodInfo& m = find_method(*method);
      std::fputs(params_markdown(m.params().specs()).c_str(), stdout);
      return 0;
    };
  });
}

}  // namespace ao::cli
