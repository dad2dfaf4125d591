// SPDX-License-Identifier: Apache-2.0
// ao compare: parses the options into a CompareRequest (ao/jobs/compare.h), runs it, and prints
// the table. docs/compare.md.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include <CLI/CLI.hpp>

#include "ao/core/closest_name.h"
#include "ao/core/error.h"
#include "ao/jobs/compare.h"
#include "ao/io/text.h"
#include "ao/io/json_text.h"
#include "ao/registry/registry.h"
#include "common.h"
#include "subcommands.h"

namespace ao::cli {

namespace {

struct CompareOptions {
  std::vector<std::string> scene;
  std::string methods;  ///< Comma-separated; empty = every approximate method in the registry.
  int spp_reference = 256;
  std::string sweep;  ///< "key=v1,v2,...".
  std::string out_dir;
  CameraOptions camera{.request = {.default_width = 640, .default_height = 360}};
  FalloffOptions falloff;
  std::string normal = "shading";
  std::uint32_t seed = 1;
  std::string device = "cpu";
  std::vector<std::string> params;  ///< method.key=value.
  std::string reference;            ///< NAME or method=NAME, comma-separated; empty = matched.
  std::string common_reference = "obscurance";
  bool json = false;
};

// -p key=value (every chosen method that has the key) or -p method.key=value (that method): each
// method's overrides over its defaults. Parameter names have no dots, so a dot before the '='
// names a method.
void parse_params(const std::vector<std::string>& params, CompareSettings& settings) {
  std::vector<std::string> chosen = settings.methods;
  if (chosen.empty())
    for (const MethodInfo& m : all_methods())
      if (!m.ground_truth) chosen.emplace_back(m.name);
  auto set = [&](const std::string& name, const std::string& kv) {
    nlohmann::json& p = settings.params[name];
    const nlohmann::json defaults = find_method(name).default_params();
    if (p.is_null()) p = defaults;
    apply_param_overrides(p, {kv}, name, defaults);
  };
  std::vector<std::string> pairs;  // -p @FILE: its parameters, each as -p key=value
  for (const std::string& kv : params) {
    if (!kv.empty() && kv[0] == '@') {
      for (std::string& p : parameter_file_pairs(kv.substr(1))) pairs.push_back(std::move(p));
    } else {
      pairs.push_back(kv);
    }
  }
  for (const std::string& kv : pairs) {
    const auto eq = kv.find('='), dot = kv.find('.');
    if (dot != std::string::npos && dot < eq) {
      if (dot == 0) throw InputError("--param: expected key=value or method.key=value, got '" + kv + "'");
      const std::string name = kv.substr(0, dot);
      if (std::find(chosen.begin(), chosen.end(), name) == chosen.end()) throw InputError("--param: method '" + name + "' is not among --methods" + did_you_mean(name, chosen));
      set(name, kv.substr(dot + 1));
      continue;
    }
    const std::string key = kv.substr(0, eq);
    bool any = false;
    std::vector<std::string> keys;  // of every chosen method, for the closest name
    for (const std::string& name : chosen) {
      const nlohmann::json defaults = find_method(name).default_params();
      if (defaults.contains(key)) set(name, kv), any = true;
      for (std::string& k : key_names(defaults)) keys.push_back(std::move(k));
    }
    if (!any)
      throw InputError("--param: no chosen method has a parameter '" + key + "' among the " + std::to_string(chosen.size()) + " methods chosen" +
                       did_you_mean(key, keys));
  }
}

CompareRequest make_request(const CompareOptions& o) {
  CompareRequest r;
  CompareSettings& settings = r.settings;
  settings.methods = split(o.methods, ',');
  if (!o.methods.empty() && settings.methods.empty()) throw InputError("--methods: no method named");
  for (const std::string& name : settings.methods) find_method(name);
  parse_params(o.params, settings);
  for (const std::string& item : split(o.reference, ',')) {
    const auto eq = item.find('=');
    if (eq == 0) throw InputError("--reference: expected NAME or method=NAME, got '" + item + "'");
    if (eq == std::string::npos) settings.references[""] = item;
    else settings.references[item.substr(0, eq)] = item.substr(eq + 1);
  }
  settings.common_reference = o.common_reference;
  settings.spp_reference = o.spp_reference;
  settings.seed = o.seed;
  settings.device = device_from_name(o.device);
  if (!o.sweep.empty()) {
    const auto eq = o.sweep.find('=');
    if (eq == std::string::npos || eq == 0) throw InputError("--sweep: expected key=v1,v2,..., got '" + o.sweep + "'");
    settings.sweep_key = o.sweep.substr(0, eq);
    for (const std::string& v : split(o.sweep.substr(eq + 1), ',')) {
      std::optional<nlohmann::json> parsed = parse_json_limited(v, "--sweep " + settings.sweep_key);
      settings.sweep_values.push_back(parsed ? std::move(*parsed) : nlohmann::json(v));
    }
  }
  r.scene.args = o.scene;
  r.camera = camera_request(o.camera);
  r.falloff = falloff_request(o.falloff);
  r.normal = surface_normal_from_name(o.normal);
  r.out_dir = o.out_dir.empty() ? default_compare_dir(r) : std::filesystem::path(o.out_dir);
  // The font of the sheet's labels: $AO_FONT when set, else DejaVu Sans where Debian installs it.
  if (const char* env = std::getenv("AO_FONT"); env != nullptr && *env != 0) r.font = env;
  return r;
}

int run(const CompareOptions& o, const GlobalOptions& global) {
  const CompareRequest request = make_request(o);
  if (global.request_only) return 0;
  StderrReporter report(global, o.json);
  const CompareJobResult out = run_compare(request, report.reporter());
  report.end_stage();
  if (o.json) {
    std::cout << out.table.dump(2) << "\n";
  } else {
    std::fprintf(stderr, "wrote %s/: table.md, table.json, sheet.png%s (R = %.4g, %s normals)\n", request.out_dir.string().c_str(),
                 out.result.sweep_key.empty() ? "" : ", sweep.md, sweep.json", out.result.falloff.radius, o.normal.c_str());
    std::cerr << out.markdown.substr(out.markdown.find("| method"));
  }
  return 0;
}

}  // namespace

void add_compare_command(CLI::App& app, const GlobalOptions& global, std::function<int()>& action) {
  auto o = std::make_shared<CompareOptions>();
  CLI::App* cmd = app.add_subcommand("compare", "Compare AO methods with the ray-traced ground truth each approximates.");
  cmd->add_option("scene", o->scene, kSceneHelp)->type_name("SCENE");
  std::string names;
  for (const MethodInfo& m : all_methods()) names += (names.empty() ? "" : ", ") + std::string(m.name);
  cmd->add_option("-m,--methods,--method", o->methods, "Comma-separated methods (" + names + "); default: every method but raytraced");
  cmd->add_option("--reference-samples,--spp-reference", o->spp_reference, "Rays per pixel of the ray-traced references")->capture_default_str();
  cmd->add_option("--sweep", o->sweep, "Also measure error against one parameter: key=v1,v2,... (e.g. samples=4,8,16,32)");
  cmd->add_option("--out-dir", o->out_dir, "Output directory (default: compare-<scene>)");
  cmd->add_option("-p,--param", o->params,
                  "Method parameter as key=value (every chosen method that has it) or method.key=value (that method); JSON value, repeatable")->type_name("KEY=VALUE");
  cmd->add_option("--reference", o->reference,
                  "Reference to judge against: NAME for every method or method=NAME, comma-separated; NAME is matched (each method's own, "
                  "the default), obscurance (the obscurance of the membership it implies), tangent-sphere or transfer");
  cmd->add_option("--common-reference", o->common_reference,
                  "The one reference every method is also judged against, so that rows can be ranked: obscurance (of --membership, "
                  "step at R by default), tangent-sphere, transfer, or none")
      ->capture_default_str();
  add_falloff_options(*cmd, o->falloff, "Falloff mu(d) requested: " + membership_names() + " (methods may imply their own)");
  add_normal_option(*cmd, o->normal, "; the same for every method and its reference");
  cmd->add_option("--seed", o->seed, "Seed of the per-pixel sample sets")->capture_default_str();
  cmd->add_option("--device", o->device,
                  "cpu, or gpu: each method also runs on the GPU backend (OpenGL 4.3 compute shaders, headless; Mesa's llvmpipe where "
                  "there is no GPU), a column per backend in the tables and the sheet (docs/gpu.md)")
      ->type_name("cpu|gpu")
      ->capture_default_str();
  add_camera_options(*cmd, o->camera);
  cmd->add_flag("--json", o->json, "Print table.json on stdout");
  cmd->footer(std::string("Environment: AO_FONT, the font file of sheet.png's labels (default ") + kDejaVuSansPath +
              "; without a readable font the sheet has no labels).");
  cmd->callback([o, &global, &action] { action = [o, &global] { return run(*o, global); }; });
}

}  // namespace ao::cli
