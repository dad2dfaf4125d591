// SPDX-License-Identifier: Apache-2.0
// ao view: the methods live in a window beside a progressive ray-traced reference (src/view/).
// Parses the same scene, camera, method and parameter options as ao render, then hands over.
#include <CLI/CLI.hpp>

#include "ao/core/error.h"
#include "ao/io/image_io.h"
#include "ao/registry/registry.h"
#include "common.h"
#include "subcommands.h"
#include "view/viewer.h"

namespace ao::cli {

namespace {

struct ViewOptions {
  std::vector<std::string> scene;
  std::string method = view::ViewSetup{}.method;
  CameraOptions camera{.request = {.default_width = 960, .default_height = 540}};
  FalloffOptions falloff;
  std::uint32_t seed = 1;
  std::string device = "cpu";
  std::vector<std::string> params;
  std::vector<std::string> sets;
  std::vector<std::string> events;
  std::string ao_map;
  int frames = 0;
  int wait_reference = 0;
  bool benchmark = false;
  bool json = false;
  std::string screenshot;
  std::string camera_out;
};

int run_view_command(const ViewOptions& o, const GlobalOptions& global) {
  const MethodInfo& method = find_method(o.method);
  nlohmann::json params = method.default_params();
  apply_param_overrides(params, o.params, method.name, method.default_params());
  if (!o.screenshot.empty() && std::filesystem::path(o.screenshot).extension() != ".png")
    throw InputError(o.screenshot + ": --screenshot writes PNG, give it a .png name");
  if (!o.camera_out.empty() && o.screenshot.empty()) throw InputError("--camera-out is written with the screenshot: give --screenshot too");
  if ((o.benchmark || o.wait_reference > 0 || !o.screenshot.empty()) && o.frames <= 0)
    throw InputError("--benchmark, --wait-reference and --screenshot belong to scripted runs: give --frames N");
  view::ViewSetup setup;
  setup.device = device_from_name(o.device);
  for (const std::string& e : o.events) setup.events.push_back(view::parse_event(e));
  const CameraRequest camera = camera_request(o.camera);
  const FalloffRequest falloff = falloff_request(o.falloff);
  if (global.request_only) return 0;
  if (!o.ao_map.empty()) setup.ao_map = read_image(o.ao_map);
  setup.scene = SceneSource{.args = o.scene}.load();
  for (const std::string& w : setup.scene->warnings) std::cerr << "warning: " << w << "\n";
  setup.camera = choose_camera(*setup.scene, camera);
  setup.radius_basis = interest_diagonal(*setup.scene);
  setup.falloff = choose_falloff(falloff, setup.radius_basis);
  setup.method = o.method;
  setup.params = params;
  setup.seed = o.seed;
  setup.threads = global.threads;
  setup.sets = o.sets;
  setup.frames = o.frames;
  setup.wait_reference_spp = o.wait_reference;
  setup.benchmark = o.benchmark;
  setup.json = o.json;
  setup.screenshot = o.screenshot;
  setup.camera_out = o.camera_out;
  return view::run_view(std::move(setup));
}

}  // namespace

void add_view_command(CLI::App& app, const GlobalOptions& global, std::function<int()>& action) {
  auto o = std::make_shared<ViewOptions>();
  CLI::App* cmd = app.add_subcommand("view", "Look at the methods live in a window, beside a progressive ray-traced reference (docs/view.md).");
  cmd->add_option("scene", o->scene, kSceneHelp)->type_name("SCENE");
  std::string methods;
  for (const MethodInfo& m : all_methods()) methods += "\n  " + std::string(m.name) + ": " + std::string(m.summary);
  cmd->add_option("-m,--method", o->method, "AO method:" + methods)->capture_default_str();
  add_falloff_options(*cmd, o->falloff, "Falloff mu(d): " + membership_names());
  cmd->add_option("--seed", o->seed, "Seed of the per-pixel sample sets")->capture_default_str();
  cmd->add_option("--device", o->device, "Where the method runs at the start: cpu, or gpu (the GPU backend in the window's OpenGL 4.3 context)")
      ->type_name("cpu|gpu")
      ->capture_default_str();
  add_camera_options(*cmd, o->camera, "Window");
  cmd->add_option("-p,--param", o->params, "Method parameter as key=value, repeatable (as ao render)")->type_name("KEY=VALUE");
  cmd->add_option("--ao-map", o->ao_map, "A baked AO map to show on the mesh (view 'map')");
  cmd->add_option("--set", o->sets,
                  "A viewer setting or method parameter as key=value before the first frame: method, view (ao, shaded, transfer, map, error), "
                  "wipe (0-1), scale (1, 2, 4), device (cpu, gpu), seed, threads, radius, radius_fraction, membership, up (y, z), "
                  "panel (open, collapsed, off), hud (on, off), reference (on, off: with --benchmark), or any -p key");
  cmd->add_option("--event", o->events, "Scripted input FRAME:KIND:ARGS, repeatable: orbit:dx,dy  pan:dx,dy  zoom:steps  key:K  set:key=value");
  cmd->add_option("--frames", o->frames, "Render this many frames and exit (scripts, tests, benchmarks)")->check(CLI::Range(0, 1000000));
  cmd->add_option("--wait-reference", o->wait_reference, "With --frames: go on until the reference has this many rays per pixel (with --benchmark, only if --set reference=on)")
      ->check(CLI::Range(0, 4096));
  cmd->add_flag("--benchmark", o->benchmark, "With --frames: recompute the G-buffer and the method every frame, as a moving camera does");
  cmd->add_option("--screenshot", o->screenshot, "With --frames: write the last frame as PNG");
  cmd->add_option("--camera-out", o->camera_out, "With --screenshot: also write the camera as JSON (ao render --camera reads it)");
  cmd->add_flag("--json", o->json, "On exit, print per-stage ms, fps and the reference's state as JSON on stdout");
  cmd->callback([o, &global, &action] { action = [o, &global] { return run_view_command(*o, global); }; });
}

}  // namespace ao::cli
