// SPDX-License-Identifier: Apache-2.0
// ao tune: parses the options into a TuneRequest (ao/jobs/tune.h), runs it, and says what it
// found. docs/compare.md#ao-tune.
#include <cstdio>
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#include "ao/core/error.h"
#include "ao/jobs/tune.h"
#include "ao/registry/registry.h"
#include "common.h"
#include "subcommands.h"

namespace ao::cli {

namespace {

struct TuneOptions {
  TuneRequest request;
  std::string scenes = "default";   ///< Comma-separated.
  std::vector<std::string> fit;     ///< key or key=lo:hi.
  std::vector<std::string> params;  ///< key=value: the starting point.
  CameraOptions camera{.request = {.default_width = 320, .default_height = 180}};
  FalloffOptions falloff;
  std::string normal = "shading";
  bool json = false;
};

// "key" (the table's range) or "key=lo:hi".
TuneFit parse_fit(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == 0) throw InputError("--fit: expected key or key=lo:hi, got '" + text + "'");
  TuneFit f{.key = text.substr(0, eq)};
  if (eq == std::string::npos) return f;
  const auto colon = text.find(':', eq);
  if (colon == std::string::npos) throw InputError("--fit: expected key or key=lo:hi, got '" + text + "'");
  try {
    f.lo = std::stod(text.substr(eq + 1, colon - eq - 1));
    f.hi = std::stod(text.substr(colon + 1));
  } catch (const std::exception&) {
    throw InputError("--fit: lo and hi of '" + f.key + "' must be numbers, got '" + text + "'");
  }
  return f;
}

int run(const TuneOptions& o, const GlobalOptions& global) {
  TuneRequest r = o.request;
  const MethodInfo& m = find_method(r.method);
  apply_param_overrides(r.params, o.params, m.name, m.default_params());
  for (const std::string& p : o.params)
    if (p.starts_with("@")) r.parameter_files.emplace_back(p.substr(1));
  for (const std::string& f : o.fit) r.fit.push_back(parse_fit(f));
  r.scenes = split(o.scenes, ',');
  r.camera = camera_request(o.camera);
  r.falloff = falloff_request(o.falloff);
  r.normal = surface_normal_from_name(o.normal);
  if (r.output.empty() && !o.json) throw InputError("-o: name the parameter file to write (or print it with --json)");
  if (global.request_only) return 0;
  StderrReporter report(global, o.json);
  const TuneJobResult out = run_tune(r, report.reporter());
  report.end_stage();
  if (o.json) {
    std::cout << out.file.dump(2) << "\n";
    return 0;
  }
  std::fprintf(stderr, "mean RMSE %.4f -> %.4f in %d evaluations (%.1f s); wrote %s (load with -p @%s)\n", out.tune.start_rmse, out.tune.best_rmse,
               out.tune.evaluations, out.tune.seconds, r.output.string().c_str(), r.output.string().c_str());
  return 0;
}

}  // namespace

void add_tune_command(CLI::App& app, const GlobalOptions& global, std::function<int()>& action) {
  auto o = std::make_shared<TuneOptions>();
  CLI::App* cmd = app.add_subcommand("tune", "Fit a method's parameters to its matched reference over several scenes (coordinate descent on RMSE).");
  cmd->add_option("-m,--method", o->request.method, "Method to tune")->required();
  cmd->add_option("--fit", o->fit, "Parameter to fit: key (within its valid range) or key=lo:hi, repeatable (e.g. intensity=0.1:2)")->required();
  cmd->add_option("--scenes", o->scenes, "Comma-separated scenes, one view each (built-in names or mesh files)")->capture_default_str();
  cmd->add_option("-p,--param", o->params, "Starting value of a parameter: key=value, repeatable")->type_name("KEY=VALUE");
  cmd->add_option("--budget", o->request.budget_s, "Time budget, seconds")->capture_default_str();
  cmd->add_option("--reference-samples,--spp-reference", o->request.spp_reference, "Rays per pixel of the references")->capture_default_str();
  cmd->add_option("-o,--output", o->request.output, "Parameter file to write (JSON; load with -p @FILE); required unless --json");
  add_falloff_options(*cmd, o->falloff, "Falloff mu(d) requested: " + membership_names(), false);
  add_normal_option(*cmd, o->normal, "; the same for the method and its reference");
  add_camera_options(*cmd, o->camera);  // every scene's view; without --eye/--camera each scene is framed on its own
  cmd->add_flag("--json", o->json, "Print the parameter file's content on stdout");
  cmd->add_option("--seed", o->request.seed, "Seed of the per-pixel sample sets")->capture_default_str();
  cmd->callback([o, &global, &action] { action = [o, &global] { return run(*o, global); }; });
}

}  // namespace ao::cli
