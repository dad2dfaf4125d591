// SPDX-License-Identifier: Apache-2.0
// ao render: parses the options into a RenderRequest (ao/jobs/render.h), runs it, and prints the
// summary line or the JSON summary.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/core/membership.h"
#include "ao/io/image_io.h"
#include "ao/jobs/render.h"
#include "ao/registry/registry.h"
#include "common.h"
#include "subcommands.h"

namespace ao::cli {

namespace {

struct RenderOptions {
  RenderRequest request;  ///< Filled directly where the types allow.
  std::vector<std::string> scene;
  std::string output, shaded, gbuffer_out, gbuffer_in, ao_map;
  CameraOptions camera;
  FalloffOptions falloff;
  std::optional<std::string> normal;
  std::vector<std::string> params;  ///< key=value overrides of the method's parameters.
  std::optional<std::string> sun;   ///< "DX,DY,DZ[,E]".
  std::string device = "cpu";
  bool json = false;
};

// --sun DX,DY,DZ[,E]: the direction towards the sun in world space (any non-zero length,
// normalised here) and optionally its irradiance E in units of La (default pi, see
// direct_light.h). One-line InputErrors for a wrong count, non-numbers, non-finite values, a
// zero direction and a negative E.
Sun parse_sun(const std::string& text) {
  const std::vector<std::string> items = [&] {
    std::vector<std::string> v;
    for (std::size_t start = 0;;) {
      const std::size_t comma = text.find(',', start);
      v.push_back(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
      if (comma == std::string::npos) return v;
      start = comma + 1;
    }
  }();
  if (items.size() != 3 && items.size() != 4)
    throw InputError("--sun: expected DX,DY,DZ (towards the sun) or DX,DY,DZ,E, 3 or 4 numbers, got '" + text + "'");
  std::vector<double> v;
  for (const std::string& item : items) {
    char* end = nullptr;
    const double x = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size())
      throw InputError("--sun: '" + item + "' is not a number (expected DX,DY,DZ or DX,DY,DZ,E)");
    if (!std::isfinite(x) || std::abs(x) > 3.0e38) throw InputError("--sun: '" + item + "' is not a finite float");
    v.push_back(x);
  }
  const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!(len > 0)) throw InputError("--sun: the direction " + text + " has no length: give the direction towards the sun, e.g. 1,2,1");
  Sun sun;
  sun.direction = {static_cast<float>(v[0] / len), static_cast<float>(v[1] / len), static_cast<float>(v[2] / len)};
  if (v.size() == 4) {
    if (!(v[3] >= 0))
      throw InputError("--sun: the irradiance E must be >= 0 (units of the ambient radiance; pi: as bright as the sky), got " + items[3]);
    sun.irradiance = static_cast<float>(v[3]);
  }
  sun.validate();
  return sun;
}

RenderRequest make_request(const RenderOptions& o) {
  RenderRequest r = o.request;
  const MethodInfo& method = find_method(r.method);
  r.scene.args = o.scene;
  r.gbuffer_file = o.gbuffer_in;
  r.ao_map = o.ao_map;
  r.camera = camera_request(o.camera);
  r.falloff = falloff_request(o.falloff);
  if (o.normal) r.normal = surface_normal_from_name(*o.normal);
  apply_param_overrides(*r.params, o.params, method.name, o.ao_map.empty() ? method.default_params() : nlohmann::json::object());
  if (o.sun) r.sun = parse_sun(*o.sun);
  r.device = device_from_name(o.device);
  r.outputs.visibility = o.output;
  r.outputs.shaded = o.shaded;
  r.outputs.gbuffer = o.gbuffer_out;
  if (r.outputs.visibility.empty()) r.outputs.visibility = default_render_output(r);
  return r;
}

void print_summary(const RenderResult& out) {
  std::fprintf(stderr, "wrote %s: %s, %s, %dx%d, R = %.4g (%s), mean V = %.4f, %.0f ms\n", out.summary["output"].get<std::string>().c_str(),
               out.scene.c_str(), out.method.c_str(), out.gbuffer.width(), out.gbuffer.height(), out.falloff.radius,
               std::string(to_string(out.falloff.membership)).c_str(), out.mean_visibility, out.method_ms);
  const nlohmann::json& stats = out.output.stats;
  if (stats.contains("mean_std_error"))
    std::fprintf(stderr, "  standard error: mean %.4f, max %.4f; %.1f M rays/s\n", stats["mean_std_error"].get<double>(),
                 stats["max_std_error"].get<double>(), out.summary->value("rays_per_second", 0.0) / 1e6);
  if (out.device == Device::Gpu)
    std::fprintf(stderr, "  GPU %s: %s\n", out.gl_renderer.c_str(), describe_gpu_passes(out.gpu_passes).c_str());
}

int run(const RenderOptions& o, const GlobalOptions& global) {
  const RenderRequest request = make_request(o);
  if (global.request_only) return 0;
  StderrReporter report(global, o.json);
  const RenderResult out = run_render(request, report.reporter());
  report.end_stage();
  if (o.json) std::cout << out.summary->dump(2) << "\n";
  else print_summary(out);
  return 0;
}

}  // namespace

void add_render_command(CLI::App& app, const GlobalOptions& global, std::function<int()>& action) {
  auto o = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand("render", "Render an AO image of a scene (or of a G-buffer EXR).");
  cmd->add_option("scene", o->scene, kSceneHelp)->type_name("SCENE");
  cmd->add_option("-o,--output", o->output, "Visibility image: " + supported_image_extensions() + " (.exr float; the others 8 or 16 bit where the format has it, linear V). Default: <scene>-<method>.png");
  std::string methods;
  for (const MethodInfo& m : all_methods()) methods += "\n  " + std::string(m.name) + ": " + std::string(m.summary);
  cmd->add_option("-m,--method", o->request.method, "AO method:" + methods)->capture_default_str();
  add_falloff_options(*cmd, o->falloff, "Falloff mu(d): " + membership_names());
  add_normal_option(*cmd, o->normal, "");
  cmd->add_option("--samples,--spp", o->request.samples,
                  "Samples per pixel (default: the method's own; 256 rays for raytraced, the maximum with --target-error)");
  cmd->add_option("--target-error", o->request.target_error, "Stop a pixel once its standard error is below this (raytraced; default off)");
  cmd->add_option("--seed", o->request.seed, "Seed of the per-pixel sample sets")->capture_default_str();
  cmd->add_option("--device", o->device,
                  "Where the method runs: cpu, or gpu (OpenGL 4.3 compute shaders on this render's G-buffer, headless; Mesa's llvmpipe "
                  "where there is no GPU; docs/gpu.md)")
      ->type_name("cpu|gpu")
      ->capture_default_str();
  add_camera_options(*cmd, o->camera);
  cmd->add_option("--shaded", o->shaded,
                  "Also write albedo x ambient x V with a soft key light, for viewing (sRGB); transfer: a W La. With --sun (or direct.* "
                  "in --gbuffer-in) the sun replaces the key light: (a V + Ld) La, transfer (a W + Ld) La");
  cmd->add_option("--sun", o->sun,
                  "Direct-light pass: a sun towards world direction DX,DY,DZ (normalised), with shadow rays; E = its irradiance in "
                  "units of the ambient radiance, >= 0 (default pi: as bright as the sky). Used by --shaded, by transfer's "
                  "-p reflectance=radiance, and stored by --gbuffer-out")
      ->type_name("DX,DY,DZ[,E]");
  cmd->add_option("--gbuffer-out", o->gbuffer_out, "Also write the G-buffer as a multi-channel EXR (docs/gbuffer.md)");
  cmd->add_option("--ao-map", o->ao_map,
                  "Show a baked AO map (from ao bake) on the scene instead of computing AO: V = the map at each pixel's UV");
  cmd->add_option("--gbuffer-in", o->gbuffer_in, "Read the G-buffer from an EXR instead of rendering a scene (screen-space methods)");
  cmd->add_option("-p,--param", o->params, "Method parameter as key=value (JSON value), repeatable; --json lists them. containment, volumetric, transfer: "
                  "characteristic=depth|implicit|height-field|'depth*height-field' (docs/methods/containment.md)")->type_name("KEY=VALUE");
  cmd->add_option("--png-bits", o->request.outputs.png_bits, "PNG bit depth, 8 or 16")->capture_default_str();
  cmd->add_flag("--extras", o->request.outputs.extras,
                "Also write the method's extra outputs (transfer: obscurance; alchemy: unfiltered) as <output-stem>-<name><ext>");
  cmd->add_flag("--json", o->json, "Print a JSON summary (parameters, timings, rays/s, mean V, errors) on stdout");
  cmd->add_flag("--provenance", o->request.outputs.provenance,
                "Also write beside each output FILE its record FILE.ao.json: ao's version and SIMD target, the inputs' SHA-256, every setting "
                "(docs/cluster.md, \"Provenance\")");
  cmd->callback([o, &global, &action] { action = [o, &global] { return run(*o, global); }; });
}

}  // namespace ao::cli
