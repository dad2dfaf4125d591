// ao render: scene (or G-buffer EXR) -> AO image, with optional G-buffer, shaded image and JSON.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include <CLI/CLI.hpp>

#include "ao/core/error.h"
#include "ao/core/memory.h"
#include "ao/eval/shading.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/io/gbuffer_exr.h"
#include "ao/io/image_io.h"
#include "ao/io/output_set.h"
#include "ao/registry/registry.h"
#include "ao/reference/direct_light.h"
#include "ao/reference/ray_scene.h"
#include "common.h"
#include "subcommands.h"

namespace ao::cli {

namespace {

struct RenderOptions {
  std::vector<std::string> scene;
  std::string method = "raytraced";
  std::string output;
  std::string shaded;
  std::string gbuffer_out;
  std::string gbuffer_in;
  std::string ao_map;
  CameraOptions camera;
  FalloffOptions falloff;
  std::optional<std::string> normal;  ///< --normal shading|geometric (GBufferOptions::normal); default shading.
  std::optional<int> samples;         ///< Overrides the method's own default sample count.
  std::optional<float> target_error;
  std::uint32_t seed = 1;
  std::vector<std::string> params;  ///< key=value overrides of the method's parameters.
  std::optional<std::string> sun;   ///< "DX,DY,DZ[,E]": a direct-light pass (parse_sun).
  int png_bits = 8;
  bool json = false;
  bool extras = false;  ///< Also write the method's extra outputs (MethodOutput::extras) beside the output.
};

// --sun DX,DY,DZ[,E]: the direction towards the sun in world space (any non-zero length,
// normalised here) and optionally its irradiance E in units of La (default pi, see
// direct_light.h). One-line InputErrors for a wrong count, non-numbers, non-finite values, a
// zero direction and a negative E.
Sun parse_sun(const std::string& text) {
  std::vector<std::string> items;
  for (std::size_t start = 0;;) {
    const std::size_t comma = text.find(',', start);
    items.push_back(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
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

// The parameters ask for transfer's radiance mode (transfer.h), which reads the direct-light pass.
bool wants_direct_pass(const nlohmann::json& params) {
  return params.is_object() && params.contains("reflectance") && params["reflectance"] == "radiance";
}

std::string default_output(const std::string& scene_name, const std::string& method) {
  std::string stem = std::filesystem::path(scene_name).stem().string();
  if (stem.empty()) stem = "gbuffer";
  return stem + "-" + method + ".png";
}

int run_render(const RenderOptions& o, const GlobalOptions& global) {
  Stopwatch clock;
  nlohmann::json timings;
  const bool progress = !global.quiet && stderr_is_terminal();
  // Every option is checked before any file is read, so a typo costs nothing.
  const MethodInfo& method = find_method(o.method);
  const std::string method_name = o.ao_map.empty() ? std::string(method.name) : "ao-map";
  if (!o.gbuffer_in.empty() && !o.scene.empty()) throw InputError("give either a scene or --gbuffer-in, not both");
  if (!o.ao_map.empty() && !o.gbuffer_in.empty()) throw InputError("--ao-map needs the scene's UVs: give a scene, not --gbuffer-in");
  if (!o.ao_map.empty() && o.method != "raytraced") throw InputError("--ao-map shows a baked map instead of a method: drop --method");
  if (o.png_bits != 8 && o.png_bits != 16) throw InputError("--png-bits must be 8 or 16, got " + std::to_string(o.png_bits));
  for (const std::string& out : {o.output, o.shaded})
    if (!out.empty() && !is_supported_image_path(out))
      throw InputError(out + ": unknown image extension (supported: " + supported_image_extensions() + ")");
  if (!o.gbuffer_out.empty() && std::filesystem::path(o.gbuffer_out).extension() != ".exr")
    throw InputError(o.gbuffer_out + ": --gbuffer-out writes OpenEXR, give it a .exr name");
  if (!o.gbuffer_in.empty() && method.needs_scene)
    throw InputError("method " + std::string(method.name) + " traces rays in the scene, and --gbuffer-in gives only a G-buffer: pass a scene instead");
  check_camera_options(o.camera, /*size_given=*/o.gbuffer_in.empty());
  check_falloff_options(o.falloff);
  nlohmann::json params = o.ao_map.empty() ? method.default_params() : nlohmann::json::object();
  // --spp and --target-error set the method's parameters of those names when given; otherwise
  // each method keeps its own default (256 rays for raytraced, the paper's count for the others).
  if (o.samples) {
    if (!params.contains("samples")) throw InputError("--spp: method " + std::string(method.name) + " has no sample count");
    params["samples"] = *o.samples;
  }
  if (o.target_error) {
    if (!params.contains("target_error")) throw InputError("--target-error: only the ray-traced method stops adaptively");
    params["target_error"] = *o.target_error;
  }
  apply_param_overrides(params, o.params, method.name);
  if (o.normal && !o.gbuffer_in.empty())
    throw InputError("--normal chooses the normal a scene's G-buffer is rendered with; a --gbuffer-in file brings its own N");
  const std::optional<Sun> sun = o.sun ? std::optional<Sun>(parse_sun(*o.sun)) : std::nullopt;
  // Only the channels something reads: screen-space methods (transfer, GTAO's multi-bounce), the
  // sun, --shaded and --gbuffer-out read the albedo; the ray tracers take it from the scene. UVs
  // serve --ao-map only.
  const GBufferOptions gbuffer_options{.normal = o.normal ? parse_surface_normal(*o.normal) : SurfaceNormal::Shading,
                                       .albedo = !method.needs_scene || sun || !o.shaded.empty() || !o.gbuffer_out.empty(),
                                       .uv = !o.ao_map.empty()};
  if (sun && !o.gbuffer_in.empty())
    throw InputError("--sun traces shadow rays in the scene, and --gbuffer-in gives only a G-buffer: give a scene, or a G-buffer EXR with "
                     "direct.R direct.G direct.B channels");
  const bool radiance_mode = o.ao_map.empty() && wants_direct_pass(params);
  if (radiance_mode && !sun && o.gbuffer_in.empty())
    throw InputError("-p reflectance=radiance reads the occluders' direct light: give a sun with --sun DX,DY,DZ[,E] (or --gbuffer-in "
                     "with direct.R direct.G direct.B channels)");

  // All outputs are declared before the work: one that names an input or another output is
  // refused now, and they are renamed into place together at the end (OutputSet).
  const std::string output =
      o.output.empty() ? default_output(o.gbuffer_in.empty() ? scene_arguments_name(o.scene) : o.gbuffer_in, method_name) : o.output;
  OutputSet outputs;
  add_scene_inputs(outputs, o.scene);
  outputs.add_input(o.gbuffer_in, "--gbuffer-in");
  outputs.add_input(o.ao_map, "--ao-map");
  outputs.add_output(output, o.output.empty() ? "the default output" : "-o");
  if (!o.shaded.empty()) outputs.add_output(o.shaded, "--shaded");
  if (!o.gbuffer_out.empty()) outputs.add_output(o.gbuffer_out, "--gbuffer-out");
  // Cone tracing's voxel grid, from its parameters (their types and ranges are checked by the method).
  std::uint64_t grid_bytes = 0;
  if (method.name == "cone" && o.ao_map.empty() && params.value("columns", nlohmann::json()).is_number_integer() &&
      params.value("depth_bits", nlohmann::json()).is_number_integer())
    grid_bytes = estimate_cone_grid_memory(params["columns"].get<int>(), params["depth_bits"].get<int>());
  if (o.gbuffer_in.empty())
    check_memory(estimate_render_memory({.width = o.camera.width, .height = o.camera.height, .sun = sun.has_value(),
                                         .shaded = !o.shaded.empty(), .gbuffer_out = !o.gbuffer_out.empty()}) +
                     grid_bytes,
                 "ao render: " + std::to_string(o.camera.width) + "x" + std::to_string(o.camera.height) + " pixels" +
                     (grid_bytes ? " and a " + std::to_string(params["columns"].get<int>()) + "^2 x " +
                                       std::to_string(params["depth_bits"].get<int>()) + " voxel grid"
                                 : std::string()));

  const Image<float> ao_map = o.ao_map.empty() ? Image<float>() : read_image(o.ao_map);
  std::optional<Scene> scene;
  std::unique_ptr<RayScene> rays;
  GBuffer g;
  float diagonal = 0;
  if (!o.gbuffer_in.empty()) {
    g = read_gbuffer_exr(o.gbuffer_in, {.vertical_fov_deg = o.camera.fov});
    timings["load_gbuffer_ms"] = clock.lap_ms();
    Bounds3 b;
    for (std::size_t i = 0; i < g.position.size(); ++i)
      if (g.covered(i)) b.extend(g.position[i]);
    diagonal = b.diagonal();
  } else {
    scene = load_scene_arguments(o.scene);
    for (const std::string& w : scene->warnings) std::cerr << "warning: " << w << "\n";
    timings["load_ms"] = clock.lap_ms();
    check_memory(estimate_ray_scene_memory(scene->stored_triangle_count(), scene->vertex_count(), scene->instances.size()),
                 "ao render: the BVH of " + std::to_string(scene->stored_triangle_count()) + " triangles");
    rays = std::make_unique<RayScene>(*scene);
    timings["bvh_ms"] = clock.lap_ms();
    const Camera cam = choose_camera(*scene, o.camera);
    {
      ProgressBar bar("G-buffer", progress);
      g = render_gbuffer(*rays, cam, gbuffer_options, bar.callback());
    }
    timings["gbuffer_ms"] = clock.lap_ms();
    diagonal = interest_diagonal(*scene);
    if (sun) {
      ProgressBar bar("sun", progress);
      g.direct = render_direct_light(*rays, g, *sun, bar.callback());
      timings["direct_ms"] = clock.lap_ms();
    }
  }
  if (radiance_mode && g.direct.empty())
    throw InputError(o.gbuffer_in + ": -p reflectance=radiance reads the occluders' direct light, and the file has no direct.R direct.G "
                     "direct.B channels (docs/gbuffer.md)");
  const Falloff falloff = choose_falloff(o.falloff, diagonal);

  MethodOutput result;
  if (!ao_map.empty()) {
    result.visibility = visibility_from_ao_map(g, *scene, ao_map, o.ao_map);
    result.stats = {{"ao_map", o.ao_map}, {"map_width", ao_map.width()}, {"map_height", ao_map.height()}};
  } else {
    ProgressBar bar(method_name, progress);
    result = method.run(MethodInput{g, rays.get(), falloff, o.seed, bar.callback(), scene ? &scene->analytic : nullptr}, params);
  }
  const double ao_ms = clock.lap_ms();
  timings["ao_ms"] = ao_ms;
  // Methods report problems they worked around (e.g. cone: open meshes, odd voxel columns).
  if (result.stats.contains("warnings"))
    for (const auto& w : result.stats["warnings"]) std::cerr << "warning: " << w.get<std::string>() << "\n";

  const ImageWriteOptions write_opt{.png_bits = o.png_bits};
  outputs.write(output, [&] { write_image(output, result.visibility, write_opt); });
  if (!o.shaded.empty())
    outputs.write(o.shaded, [&] { write_rgb_image(o.shaded, shade_for_display(g, result.visibility, result.color), {.png_bits = o.png_bits, .srgb = true}); });
  nlohmann::json extras_written = nlohmann::json::object();
  if (o.extras)
    for (const auto& extra : result.extras) {  // <output-stem>-<name><ext>, beside the output
      const std::string& name = extra.first;
      const auto& image = extra.second;  // a named reference: Clang 14 cannot capture structured bindings
      const std::filesystem::path out_path(output);
      const std::filesystem::path path = out_path.parent_path() / (out_path.stem().string() + "-" + name + out_path.extension().string());
      outputs.write(path, [&] { write_image(path, image, write_opt); }, "--extras");
      extras_written[name] = path.string();
    }
  if (!o.gbuffer_out.empty()) outputs.write(o.gbuffer_out, [&] { write_gbuffer_exr(o.gbuffer_out, g); });
  outputs.commit();
  timings["write_ms"] = clock.lap_ms();

  double sum_v = 0;
  std::size_t covered = 0;
  for (std::size_t i = 0; i < g.object_id.size(); ++i)
    if (g.covered(i)) {
      sum_v += result.visibility[i];
      ++covered;
    }
  const double mean_v = covered ? sum_v / static_cast<double>(covered) : 1.0;

  nlohmann::json summary = {
      {"scene", scene ? scene->name : o.gbuffer_in},
      {"method", method_name},
      {"parameters", params},
      {"membership", to_string(falloff.membership)},
      {"radius", falloff.radius},
      {"normal", o.gbuffer_in.empty() ? (gbuffer_options.normal == SurfaceNormal::Geometric ? "geometric" : "shading") : "file"},
      {"seed", o.seed},
      {"width", g.width()},
      {"height", g.height()},
      {"camera", to_json(g.camera)},
      {"covered_pixels", covered},
      {"mean_visibility", mean_v},
      {"timings", timings},
      {"output", output},
      {"extras", extras_written},
      {"stats", result.stats},
  };
  if (falloff.membership == Membership::Exp) summary["tau"] = falloff.effective_tau();
  if (sun) summary["sun"] = {{"direction", to_json(sun->direction)}, {"irradiance", sun->irradiance}};
  if (scene) {
    summary["triangles"] = scene->triangle_count();
    summary["instances"] = scene->instances.size();
    summary["warnings"] = scene->warnings;
  }
  if (result.stats.contains("rays") && ao_ms > 0)
    summary["rays_per_second"] = result.stats["rays"].get<double>() / (ao_ms / 1000.0);
  if (o.json) {
    std::cout << summary.dump(2) << "\n";
  } else {
    std::fprintf(stderr, "wrote %s: %s, %s, %dx%d, R = %.4g (%s), mean V = %.4f, %.0f ms\n", output.c_str(), summary["scene"].get<std::string>().c_str(),
                 method_name.c_str(), g.width(), g.height(), falloff.radius, std::string(to_string(falloff.membership)).c_str(), mean_v,
                 ao_ms);
    if (result.stats.contains("mean_std_error"))
      std::fprintf(stderr, "  standard error: mean %.4f, max %.4f; %.1f M rays/s\n", result.stats["mean_std_error"].get<double>(),
                   result.stats["max_std_error"].get<double>(), summary.value("rays_per_second", 0.0) / 1e6);
  }
  return 0;
}

}  // namespace

void add_render_command(CLI::App& app, const GlobalOptions& global, std::function<int()>& action) {
  auto o = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand("render", "Render an AO image of a scene (or of a G-buffer EXR).");
  cmd->add_option("scene", o->scene, kSceneHelp)
      ->type_name("SCENE");
  cmd->add_option("-o,--output", o->output, "Visibility image: .png (linear, 8 or 16 bit) or .exr (float). Default: <scene>-<method>.png");
  std::string methods;
  for (const MethodInfo& m : all_methods()) methods += "\n  " + std::string(m.name) + ": " + std::string(m.summary);
  cmd->add_option("-m,--method", o->method, "AO method:" + methods)->capture_default_str();
  cmd->add_option("--membership", o->falloff.membership, "Falloff mu(d): " + membership_names())->capture_default_str();
  cmd->add_option("-R,--radius", o->falloff.radius,
                  "Neighbourhood radius R, world units (default: --radius-fraction x the diagonal of the objects: the meshes that are not "
                  "flat, so a ground plane or walls do not change it; with --gbuffer-in, of the visible points)");
  cmd->add_option("--radius-fraction", o->falloff.radius_fraction, "R as a fraction of that diagonal, when --radius is not given")
      ->capture_default_str();
  cmd->add_option("--normal", o->normal, std::string(kNormalHelp) + " (default: shading)")->type_name("shading|geometric");
  cmd->add_option("--tau", o->falloff.tau, "Absorption coefficient of the exp membership, 1/world units (0: 3/R)")->capture_default_str();
  cmd->add_option("--spp,--samples", o->samples,
                  "Samples per pixel (default: the method's own; 256 rays for raytraced, the maximum with --target-error)");
  cmd->add_option("--target-error", o->target_error, "Stop a pixel once its standard error is below this (raytraced; default off)");
  cmd->add_option("--seed", o->seed, "Seed of the per-pixel sample sets")->capture_default_str();
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
                  "characteristic=depth|implicit|height-field|'depth*height-field' (docs/methods/containment.md)");
  cmd->add_option("--png-bits", o->png_bits, "PNG bit depth, 8 or 16")->capture_default_str();
  cmd->add_flag("--extras", o->extras,
                "Also write the method's extra outputs (transfer: obscurance; alchemy: unfiltered) as <output-stem>-<name><ext>");
  cmd->add_flag("--json", o->json, "Print a JSON summary (parameters, timings, rays/s, mean V, errors) on stdout");
  cmd->callback([o, &global, &action, cmd] {
    note_camera_size_given(*cmd, o->camera);
    action = [o, &global] { return run_render(*o, global); };
  });
}

}  // namespace ao::cli
