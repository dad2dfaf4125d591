// ao compare: the command-line shell of the comparison pipeline (ao/jobs/compare.h): parses the
// options, renders the G-buffer, calls compare_methods, and writes its table (Markdown and JSON),
// the contact sheet and optionally the sweep. docs/compare.md.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include <CLI/CLI.hpp>

#include "ao/core/error.h"
#include "ao/jobs/compare.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/io/atomic_file.h"
#include "ao/io/image_io.h"
#include "ao/io/output_set.h"
#include "ao/io/text.h"
#include "ao/registry/registry.h"
#include "ao/reference/ray_scene.h"
#include "common.h"
#include "contact_sheet.h"
#include "subcommands.h"

namespace ao::cli {

namespace {

namespace fs = std::filesystem;

struct CompareOptions {
  std::vector<std::string> scene;
  std::string methods;               ///< Comma-separated; empty = every approximate method in the registry.
  int spp_reference = 256;
  std::string sweep;                 ///< "key=v1,v2,...".
  std::string out_dir;
  CameraOptions camera{.width = 640, .height = 360};
  FalloffOptions falloff;
  std::string normal = "shading";    ///< --normal: GBufferOptions::normal.
  std::uint32_t seed = 1;
  std::vector<std::string> params;   ///< method.key=value.
  std::string reference;             ///< NAME or method=NAME, comma-separated; empty = matched.
  bool json = false;
};

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

// The font of the sheet's labels: $AO_FONT when set, else DejaVu Sans where Debian installs it.
fs::path sheet_font_path() {
  const char* env = std::getenv("AO_FONT");
  return env != nullptr && *env != 0 ? fs::path(env) : fs::path(kDejaVuSansPath);
}

void write_text(const fs::path& path, const std::string& text) {
  write_file_atomically(path, [&](const fs::path& temp) {
    std::ofstream out(temp, std::ios::binary);
    out << text;
    out.close();
    if (!out) throw SystemError(path.string() + ": cannot write");
  });
}

int run_compare(const CompareOptions& o, const GlobalOptions& global) {
  const bool progress = !global.quiet && stderr_is_terminal();

  // Everything that can be checked without rendering is checked before anything is written.
  CompareSettings settings;
  settings.methods = split(o.methods, ',');
  if (!o.methods.empty() && settings.methods.empty()) throw InputError("--methods: no method named");
  for (const std::string& name : settings.methods) find_method(name);
  for (const std::string& kv : o.params) {
    const auto dot = kv.find('.');
    if (dot == std::string::npos || dot == 0) throw InputError("--param: expected method.key=value, got '" + kv + "'");
    const std::string name = kv.substr(0, dot);
    if (!settings.methods.empty() && std::find(settings.methods.begin(), settings.methods.end(), name) == settings.methods.end())
      throw InputError("--param: method '" + name + "' is not among --methods");
    nlohmann::json& p = settings.params[name];
    if (p.is_null()) p = find_method(name).default_params();
    apply_param_overrides(p, {kv.substr(dot + 1)}, name);
  }
  for (const std::string& item : split(o.reference, ',')) {
    const auto eq = item.find('=');
    if (eq == 0) throw InputError("--reference: expected NAME or method=NAME, got '" + item + "'");
    if (eq == std::string::npos)
      settings.references[""] = item;
    else
      settings.references[item.substr(0, eq)] = item.substr(eq + 1);
  }
  settings.spp_reference = o.spp_reference;
  settings.seed = o.seed;
  if (!o.sweep.empty()) {
    const auto eq = o.sweep.find('=');
    if (eq == std::string::npos || eq == 0) throw InputError("--sweep: expected key=v1,v2,..., got '" + o.sweep + "'");
    settings.sweep_key = o.sweep.substr(0, eq);
    for (const std::string& v : split(o.sweep.substr(eq + 1), ',')) {
      nlohmann::json parsed = nlohmann::json::parse(v, nullptr, false);
      settings.sweep_values.push_back(parsed.is_discarded() ? nlohmann::json(v) : parsed);
    }
  }
  settings = resolve_compare_settings(settings);  // R is set below; the check uses the default falloff

  check_camera_options(o.camera);
  check_falloff_options(o.falloff);
  // The outputs are declared before the work (refused if one names an input) and renamed into
  // place together once all are written (output_set.h); a missing folder is created then.
  const fs::path out_dir =
      o.out_dir.empty() ? fs::path("compare-" + fs::path(scene_arguments_name(o.scene)).stem().string()) : fs::path(o.out_dir);
  OutputSet outputs;
  add_scene_inputs(outputs, o.scene);
  outputs.add_directory(out_dir, "--out-dir");
  std::vector<std::string> files = {"table.json", "table.md", "sheet.png"};
  if (!settings.sweep_key.empty()) files.insert(files.end(), {"sweep.json", "sweep.md"});
  for (const std::string& f : files) outputs.add_output(out_dir / f, "--out-dir");
  auto write_output_text = [&](const std::string& name, const std::string& text) {
    outputs.write(out_dir / name, [&] { write_text(out_dir / name, text); });
  };

  Stopwatch clock;
  Scene scene = load_scene_arguments(o.scene);
  for (const std::string& w : scene.warnings) std::cerr << "warning: " << w << "\n";
  const RayScene rays(scene);
  const Camera cam = choose_camera(scene, o.camera);
  GBuffer g;
  {
    ProgressBar bar("G-buffer", progress);
    g = render_gbuffer(rays, cam, GBufferOptions{.normal = parse_surface_normal(o.normal)}, bar.callback());
  }
  settings.falloff = choose_falloff(o.falloff, interest_diagonal(scene));
  const double setup_ms = clock.lap_ms();

  // One progress bar per stage, each closed when the next starts.
  std::unique_ptr<ProgressBar> bar;
  settings.progress = [&](const std::string& stage) {
    bar.reset();
    bar = std::make_unique<ProgressBar>(stage, progress);
    return bar->callback();
  };
  const CompareResult result = compare_methods(rays, g, &scene.analytic, settings);
  bar.reset();
  // Methods report problems they worked around (e.g. cone: open meshes).
  for (const CompareRow& row : result.rows)
    if (row.stats.contains("warnings"))
      for (const auto& w : row.stats["warnings"]) std::cerr << "warning: " << row.method << ": " << w.get<std::string>() << "\n";

  nlohmann::json table = compare_table_json(result);
  table["scene"] = scene.name;
  table["camera"] = to_json(g.camera);
  table["setup_ms"] = setup_ms;
  const std::string md = compare_table_markdown(result, scene.name);

  write_output_text("table.json", table.dump(2) + "\n");
  write_output_text("table.md", md);
  std::vector<SheetRow> sheet_rows;
  for (const CompareRow& row : result.rows) {
    std::vector<std::string> label = {row.method};
    const std::string kp = compare_key_params(row);
    if (!kp.empty()) label.push_back(kp);
    label.push_back("reference: " + result.references[row.reference].spec.label());
    label.push_back("RMSE " + fixed(row.metrics.rmse, 4));  // as in table.md
    sheet_rows.push_back({&row.visibility, &result.references[row.reference].visibility, &row.heat, std::move(label)});
  }
  // A missing font costs the labels, never the comparison.
  std::string font_error;
  const std::optional<Font> font = Font::open(sheet_font_path(), &font_error);
  if (!font) std::cerr << "warning: " << font_error << "; sheet.png has no labels (install fonts-dejavu-core or set AO_FONT)\n";
  const Image<Vec3> sheet = contact_sheet(sheet_rows, kCompareHeatRange, font ? &*font : nullptr);
  outputs.write(out_dir / "sheet.png", [&] { write_rgb_image(out_dir / "sheet.png", sheet); });
  if (!result.sweep_key.empty()) {
    write_output_text("sweep.json", compare_sweep_json(result).dump(2) + "\n");
    write_output_text("sweep.md", compare_sweep_markdown(result));
  }
  outputs.commit();

  if (o.json) {
    std::cout << table.dump(2) << "\n";
  } else {
    std::fprintf(stderr, "wrote %s/: table.md, table.json, sheet.png%s (R = %.4g, %s normals)\n", out_dir.string().c_str(),
                 result.sweep_key.empty() ? "" : ", sweep.md, sweep.json", settings.falloff.radius, o.normal.c_str());
    std::cerr << md.substr(md.find("| method"));
  }
  return 0;
}

}  // namespace

void add_compare_command(CLI::App& app, const GlobalOptions& global, std::function<int()>& action) {
  auto o = std::make_shared<CompareOptions>();
  CLI::App* cmd = app.add_subcommand("compare", "Compare AO methods with the ray-traced ground truth each approximates.");
  cmd->add_option("scene", o->scene, kSceneHelp)
      ->type_name("SCENE");
  std::string names;
  for (const MethodInfo& m : all_methods()) names += (names.empty() ? "" : ", ") + std::string(m.name);
  cmd->add_option("--methods", o->methods, "Comma-separated methods (" + names + "); default: every method but raytraced");
  cmd->add_option("--spp-reference", o->spp_reference, "Rays per pixel of the ray-traced references")->capture_default_str();
  cmd->add_option("--sweep", o->sweep, "Also measure error against one parameter: key=v1,v2,... (e.g. samples=4,8,16,32)");
  cmd->add_option("--out-dir", o->out_dir, "Output directory (default: compare-<scene>)");
  cmd->add_option("-p,--param", o->params, "Method parameter as method.key=value (JSON value), repeatable");
  cmd->add_option("--reference", o->reference,
                  "Reference to judge against: NAME for every method or method=NAME, comma-separated; NAME is matched (each method's own, "
                  "the default), obscurance (the obscurance of the membership it implies), tangent-sphere or transfer");
  cmd->add_option("--membership", o->falloff.membership, "Falloff mu(d) requested: " + membership_names() + " (methods may imply their own)")
      ->capture_default_str();
  cmd->add_option("-R,--radius", o->falloff.radius,
                  "Neighbourhood radius R, world units (default: --radius-fraction x the diagonal of the objects: the meshes that are not "
                  "flat, so a ground plane or walls do not change it)");
  cmd->add_option("--radius-fraction", o->falloff.radius_fraction, "R as a fraction of that diagonal")->capture_default_str();
  cmd->add_option("--normal", o->normal, std::string(kNormalHelp) + "; the same for every method and its reference")->capture_default_str();
  cmd->add_option("--tau", o->falloff.tau, "Absorption coefficient of the exp membership, 1/world units (0: 3/R)")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of the per-pixel sample sets")->capture_default_str();
  add_camera_options(*cmd, o->camera);
  cmd->add_flag("--json", o->json, "Print table.json on stdout");
  cmd->footer(std::string("Environment: AO_FONT, the font file of sheet.png's labels (default ") + kDejaVuSansPath +
              "; without a readable font the sheet has no labels).");
  cmd->callback([o, &global, &action, cmd] {
    note_camera_size_given(*cmd, o->camera);
    action = [o, &global] { return run_compare(*o, global); };
  });
}

}  // namespace ao::cli
