// ao tune: the command-line shell of tune_method (ao/jobs/tune.h): loads the views, renders each
// one's G-buffer and matched reference, fits the chosen parameters and writes them as a parameter
// file that `ao render -p @file.json` loads. docs/compare.md#ao-tune.
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include <CLI/CLI.hpp>

#include "ao/core/error.h"
#include "ao/jobs/compare.h"
#include "ao/jobs/tune.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/io/atomic_file.h"
#include "ao/registry/registry.h"
#include "ao/reference/ray_scene.h"
#include "common.h"
#include "subcommands.h"

namespace ao::cli {

namespace {

struct TuneOptions {
  std::string scenes = "default";   ///< Comma-separated: built-in names or mesh files, one view each.
  std::string method;
  std::vector<std::string> fit;     ///< key=lo:hi.
  std::vector<std::string> params;  ///< key=value: the starting point.
  double budget_s = 60;
  int spp_reference = 256;
  std::string out;
  CameraOptions camera{.width = 320, .height = 180};
  FalloffOptions falloff;
  std::uint32_t seed = 1;
};

// "key=lo:hi" -> a parameter of the starting point's type (integer when its value is).
TuneParameter parse_fit(const std::string& text, const nlohmann::json& start) {
  const auto eq = text.find('='), colon = text.find(':');
  TuneParameter p;
  if (eq == std::string::npos || eq == 0 || colon == std::string::npos || colon < eq)
    throw InputError("--fit: expected key=lo:hi, got '" + text + "'");
  p.key = text.substr(0, eq);
  try {
    p.lo = std::stod(text.substr(eq + 1, colon - eq - 1));
    p.hi = std::stod(text.substr(colon + 1));
  } catch (const std::exception&) {
    throw InputError("--fit: lo and hi of '" + p.key + "' must be numbers, got '" + text + "'");
  }
  p.integer = start.contains(p.key) && start.at(p.key).is_number_integer();
  return p;
}

int run_tune(const TuneOptions& o, const GlobalOptions& global) {
  const MethodInfo& m = find_method(o.method);
  nlohmann::json start = m.default_params();
  apply_param_overrides(start, o.params, o.method);
  TuneSettings settings{.method = o.method, .start = start, .time_budget_s = o.budget_s, .seed = o.seed};
  for (const std::string& f : o.fit) settings.parameters.push_back(parse_fit(f, start));
  if (settings.parameters.empty()) throw InputError("--fit: name at least one parameter to fit (key=lo:hi)");
  if (o.spp_reference < 1 || o.spp_reference > (1 << 20)) throw InputError("--spp-reference must be in [1, 1048576]");
  if (o.out.empty()) throw InputError("-o: name the parameter file to write");
  const bool progress = !global.quiet && stderr_is_terminal();

  // Each view keeps its scene, BVH and G-buffer alive while tuning runs.
  struct Loaded {
    Scene scene;
    std::unique_ptr<RayScene> rays;
    GBuffer g;
  };
  std::vector<std::unique_ptr<Loaded>> loaded;
  std::vector<TuneView> views;
  const std::vector<std::string> scenes = split(o.scenes, ',');
  if (scenes.empty()) throw InputError("--scenes: no scene named");
  for (const std::string& name : scenes) {
    auto l = std::make_unique<Loaded>();
    l->scene = load_scene_arguments({name});
    l->rays = std::make_unique<RayScene>(l->scene);
    l->g = render_gbuffer(*l->rays, choose_camera(l->scene, o.camera));
    const Falloff f = choose_falloff(o.falloff, l->scene.bounds().diagonal());
    ProgressBar bar("reference (" + name + ")", progress);
    Image<float> ref = render_reference(*l->rays, l->g, m.reference(f, start), {.samples = o.spp_reference}, o.seed + 1, bar.callback())
                           .scalar.visibility;
    views.push_back({l->rays.get(), &l->g, &l->scene.analytic, f, std::move(ref)});
    loaded.push_back(std::move(l));
  }
  settings.log = [](const std::string& line) { std::cerr << line << "\n"; };
  const TuneResult r = tune_method(views, settings);

  const nlohmann::json file = {{"method", o.method},  {"parameters", r.params}, {"start_rmse", r.start_rmse}, {"best_rmse", r.best_rmse},
                               {"evaluations", r.evaluations}, {"seconds", r.seconds}, {"scenes", scenes},
                               {"width", o.camera.width}, {"height", o.camera.height}};
  write_file_atomically(o.out, [&](const std::filesystem::path& temp) {
    std::ofstream out(temp, std::ios::binary);
    out << file.dump(2) << "\n";
    out.close();
    if (!out) throw SystemError(o.out + ": cannot write");
  });
  std::fprintf(stderr, "mean RMSE %.4f -> %.4f in %d evaluations (%.1f s); wrote %s (load with -p @%s)\n", r.start_rmse, r.best_rmse,
               r.evaluations, r.seconds, o.out.c_str(), o.out.c_str());
  return 0;
}

}  // namespace

void add_tune_command(CLI::App& app, const GlobalOptions& global, std::function<int()>& action) {
  auto o = std::make_shared<TuneOptions>();
  CLI::App* cmd = app.add_subcommand("tune", "Fit a method's parameters to its matched reference over several scenes (coordinate descent on RMSE).");
  cmd->add_option("-m,--method", o->method, "Method to tune")->required();
  cmd->add_option("--fit", o->fit, "Parameter to fit and its range: key=lo:hi, repeatable (e.g. intensity=0.1:2)")->required();
  cmd->add_option("--scenes", o->scenes, "Comma-separated scenes, one view each (built-in names or mesh files)")->capture_default_str();
  cmd->add_option("-p,--param", o->params, "Starting value of a parameter: key=value, repeatable");
  cmd->add_option("--budget", o->budget_s, "Time budget, seconds")->capture_default_str();
  cmd->add_option("--spp-reference", o->spp_reference, "Rays per pixel of the references")->capture_default_str();
  cmd->add_option("-o,--output", o->out, "Parameter file to write (JSON; load with -p @FILE)")->required();
  cmd->add_option("--membership", o->falloff.membership, "Falloff mu(d) requested: " + membership_names())->capture_default_str();
  cmd->add_option("-R,--radius", o->falloff.radius, "Neighbourhood radius R, world units (default: --radius-fraction x scene diagonal)");
  cmd->add_option("--radius-fraction", o->falloff.radius_fraction, "R as a fraction of the bounding-box diagonal")->capture_default_str();
  cmd->add_option("--width", o->camera.width, "Image width, pixels")->capture_default_str();
  cmd->add_option("--height", o->camera.height, "Image height, pixels")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of the per-pixel sample sets")->capture_default_str();
  cmd->callback([o, &global, &action] { action = [o, &global] { return run_tune(*o, global); }; });
}

}  // namespace ao::cli
