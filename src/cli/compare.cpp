// ao compare: renders each approximate method and the ray-traced ground truth it approximates (same
// camera, R and membership, from the registry's reference_falloff) and writes a table (Markdown and
// JSON), a contact sheet, and optionally error against a swept parameter. docs/compare.md.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <tuple>

#include <CLI/CLI.hpp>

#include "ao/core/error.h"
#include "ao/eval/metrics.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/io/atomic_file.h"
#include "ao/io/image_io.h"
#include "ao/io/text.h"
#include "ao/methods/registry.h"
#include "ao/reference/ray_scene.h"
#include "ao/reference/raytraced.h"
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
  bool json = false;
};

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, sep))
    if (!item.empty()) out.push_back(item);
  return out;
}

// A reference is determined by its falloff; equal falloffs share one ray-traced image.
using FalloffKey = std::tuple<int, float, float, float>;
FalloffKey key_of(const Falloff& f) { return {static_cast<int>(f.membership), f.radius, f.tau, f.alchemy_u}; }

// |signed error| at which the heat map saturates, V units.
constexpr float kHeatRange = 0.25f;

struct Reference {
  Image<float> visibility;
  double ms = 0;
  double mean_std_error = 0;
};

std::string format_params(const nlohmann::json& p) {
  std::string s;
  for (const auto& [k, v] : p.items()) s += (s.empty() ? "" : ", ") + k + "=" + v.dump();
  return s;
}

std::string fixed(double v, int digits) {
  if (std::isinf(v)) return "inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

// The parameters a reader needs to tell rows apart on the contact sheet: the sample count and
// quality preset where a method has them, and whatever -p changed from the defaults. Left out when
// longer than kMaxKeyParamsChars, as table.md lists every parameter anyway.
constexpr std::size_t kMaxKeyParamsChars = 40;
std::string key_params(const nlohmann::json& p, const nlohmann::json& defaults) {
  std::string s;
  for (const auto& [k, v] : p.items()) {
    if (k != "samples" && k != "preset" && defaults.value(k, nlohmann::json()) == v) continue;
    s += (s.empty() ? "" : ", ") + k + "=" + (v.is_string() ? v.get<std::string>() : v.dump());
  }
  return s.size() <= kMaxKeyParamsChars ? s : "";
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

// All outputs go to a hidden sibling directory first and are moved into place only when every one
// of them is complete, so a failure never leaves a half-written output directory.
class StagedDir {
 public:
  explicit StagedDir(fs::path target) : target_(std::move(target)) {
    if (fs::exists(target_) && !fs::is_directory(target_)) throw InputError(target_.string() + ": exists and is not a directory");
    const fs::path parent = target_.has_parent_path() ? target_.parent_path() : fs::path(".");
    if (!fs::is_directory(parent)) throw InputError(target_.string() + ": the parent directory does not exist");
    staging_ = parent / ("." + target_.filename().string() + ".tmp-" + std::to_string(::getpid()));
    fs::remove_all(staging_);
    fs::create_directory(staging_);
  }
  ~StagedDir() {
    std::error_code ec;
    if (!committed_) fs::remove_all(staging_, ec);
  }
  fs::path file(const std::string& name) const { return staging_ / name; }
  void commit() {
    if (!fs::exists(target_)) {
      fs::rename(staging_, target_);
    } else {
      for (const auto& e : fs::directory_iterator(staging_)) fs::rename(e.path(), target_ / e.path().filename());
      fs::remove(staging_);
    }
    committed_ = true;
  }

 private:
  fs::path target_, staging_;
  bool committed_ = false;
};

int run_compare(const CompareOptions& o, const GlobalOptions& global) {
  const bool progress = !global.quiet && stderr_is_terminal();
  if (o.spp_reference < 1 || o.spp_reference > (1 << 20)) throw InputError("--spp-reference must be in [1, 1048576]");

  // Everything that can be checked without rendering is checked before anything is written.
  std::vector<const MethodInfo*> methods;
  if (o.methods.empty()) {
    // Every approximate method: the screen-space ones and cone tracing, which is compared with
    // the same ground truth (the reference itself is not compared with itself).
    for (const MethodInfo& m : all_methods())
      if (m.name != "raytraced") methods.push_back(&m);
    if (methods.empty()) throw InputError("--methods: the registry has no approximate methods");
  } else {
    for (const std::string& name : split(o.methods, ',')) methods.push_back(&find_method(name));
    if (methods.empty()) throw InputError("--methods: no method named");
  }
  std::map<std::string, nlohmann::json> params;
  for (const MethodInfo* m : methods) params[std::string(m->name)] = m->default_params();
  for (const std::string& kv : o.params) {
    const auto dot = kv.find('.');
    if (dot == std::string::npos || dot == 0)
      throw InputError("--param: expected method.key=value, got '" + kv + "'");
    const std::string name = kv.substr(0, dot);
    if (!params.count(name)) throw InputError("--param: method '" + name + "' is not among --methods");
    apply_param_overrides(params[name], {kv.substr(dot + 1)}, name);
  }
  std::string sweep_key;
  std::vector<nlohmann::json> sweep_values;
  if (!o.sweep.empty()) {
    const auto eq = o.sweep.find('=');
    if (eq == std::string::npos || eq == 0) throw InputError("--sweep: expected key=v1,v2,..., got '" + o.sweep + "'");
    sweep_key = o.sweep.substr(0, eq);
    for (const std::string& v : split(o.sweep.substr(eq + 1), ',')) {
      nlohmann::json parsed = nlohmann::json::parse(v, nullptr, false);
      sweep_values.push_back(parsed.is_discarded() ? nlohmann::json(v) : parsed);
    }
    if (sweep_values.empty()) throw InputError("--sweep: no values given for '" + sweep_key + "'");
    bool any = false;
    for (const auto& [name, p] : params) any = any || p.contains(sweep_key);
    if (!any) throw InputError("--sweep: no chosen method has a parameter '" + sweep_key + "'");
  }

  Stopwatch clock;
  Scene scene = load_scene_arguments(o.scene);
  for (const std::string& w : scene.warnings) std::cerr << "warning: " << w << "\n";
  const fs::path out_dir = o.out_dir.empty() ? fs::path("compare-" + fs::path(scene.name).stem().string()) : fs::path(o.out_dir);
  if (fs::exists(out_dir) && !fs::is_directory(out_dir)) throw InputError(out_dir.string() + ": exists and is not a directory");
  const RayScene rays(scene);
  const Camera cam = choose_camera(scene, o.camera);
  GBuffer g;
  {
    ProgressBar bar("G-buffer", progress);
    g = render_gbuffer(rays, cam, GBufferOptions{.normal = parse_surface_normal(o.normal)}, bar.callback());
  }
  const Falloff requested = choose_falloff(o.falloff, interest_diagonal(scene));
  const double setup_ms = clock.lap_ms();

  std::map<FalloffKey, Reference> references;
  auto reference_for = [&](const Falloff& f) -> const Reference& {
    auto it = references.find(key_of(f));
    if (it != references.end()) return it->second;
    ProgressBar bar("reference (" + std::string(to_string(f.membership)) + ")", progress);
    Stopwatch sw;
    RaytracedImage img = render_raytraced(rays, g, f, {.samples = o.spp_reference}, o.seed + 1, bar.callback());
    Reference r{std::move(img.visibility), sw.lap_ms(), img.mean_std_error};
    return references.emplace(key_of(f), std::move(r)).first->second;
  };
  auto run_method = [&](const MethodInfo& m, const nlohmann::json& p, double& ms) {
    ProgressBar bar(std::string(m.name), progress);
    Stopwatch sw;
    MethodOutput out = m.run(MethodInput{g, &rays, requested, o.seed, bar.callback(), &scene.analytic}, p);
    ms = sw.lap_ms();
    return out;
  };

  nlohmann::json rows = nlohmann::json::array();
  std::vector<Image<float>> images;
  std::vector<Falloff> ref_falloffs;
  std::vector<Image<Vec3>> heat;
  for (const MethodInfo* m : methods) {
    const nlohmann::json& p = params[std::string(m->name)];
    const Falloff rf = m->reference_falloff(requested, p);
    const Reference& ref = reference_for(rf);
    double ms = 0;
    MethodOutput out = run_method(*m, p, ms);
    const ErrorMetrics e = compare_images(out.visibility, ref.visibility, g.coverage);
    heat.push_back(signed_error_heat_map(out.visibility, ref.visibility, g.coverage, kHeatRange));
    nlohmann::json reference = {{"membership", to_string(rf.membership)}, {"radius", rf.radius}, {"spp", o.spp_reference},
                                {"mean_std_error", ref.mean_std_error}, {"ms", ref.ms}};
    if (rf.membership == Membership::Exp) reference["tau"] = rf.effective_tau();
    if (rf.membership == Membership::Alchemy) reference["u"] = rf.effective_alchemy_u();
    rows.push_back({{"method", m->name}, {"parameters", p}, {"ms", ms}, {"rmse", e.rmse}, {"psnr_db", e.psnr_db}, {"ssim", e.ssim},
                    {"mean_signed_error", e.mean_signed}, {"max_abs_error", e.max_abs}, {"pixels", e.pixels}, {"reference", reference},
                    {"stats", out.stats}});
    images.push_back(std::move(out.visibility));
    ref_falloffs.push_back(rf);
  }

  nlohmann::json sweep_rows = nlohmann::json::array();
  if (!sweep_key.empty())
    for (const MethodInfo* m : methods) {
      if (!params[std::string(m->name)].contains(sweep_key)) continue;
      for (const nlohmann::json& v : sweep_values) {
        nlohmann::json p = params[std::string(m->name)];
        p[sweep_key] = v;
        const Reference& ref = reference_for(m->reference_falloff(requested, p));
        double ms = 0;
        const MethodOutput out = run_method(*m, p, ms);
        const ErrorMetrics e = compare_images(out.visibility, ref.visibility, g.coverage);
        sweep_rows.push_back({{"method", m->name}, {sweep_key, v}, {"rmse", e.rmse}, {"ms", ms}});
      }
    }

  const nlohmann::json table = {{"scene", scene.name},
                                {"width", g.width()},
                                {"height", g.height()},
                                {"camera", to_json(g.camera)},
                                {"membership", to_string(requested.membership)},
                                {"radius", requested.radius},
                                {"normal", o.normal},
                                {"seed", o.seed},
                                {"spp_reference", o.spp_reference},
                                {"setup_ms", setup_ms},
                                {"rows", rows}};
  std::ostringstream md;
  md << "# ao compare: " << scene.name << "\n\n"
     << g.width() << "x" << g.height() << ", R = " << requested.radius << " (" << to_string(requested.membership) << " requested), reference "
     << o.spp_reference << " rays/pixel, seed " << o.seed << ". Errors are over covered pixels, V units; mean signed error > 0: the method is "
     << "brighter than its reference.\n\n"
     << "| method | parameters | reference | ms | RMSE | PSNR (dB) | SSIM | mean signed error |\n"
     << "|---|---|---|---:|---:|---:|---:|---:|\n";
  for (const nlohmann::json& r : rows) {
    const nlohmann::json& ref = r["reference"];
    md << "| " << r["method"].get<std::string>() << " | " << format_params(r["parameters"]) << " | " << ref["membership"].get<std::string>()
       << ", R = " << ref["radius"].get<float>() << (ref.contains("u") ? ", u = " + fixed(ref["u"].get<double>(), 4) : "") << " | "
       << fixed(r["ms"].get<double>(), 1) << " | " << fixed(r["rmse"].get<double>(), 4) << " | "
       << (r["psnr_db"].is_number() ? fixed(r["psnr_db"].get<double>(), 2) : "inf") << " | " << fixed(r["ssim"].get<double>(), 4) << " | "
       << fixed(r["mean_signed_error"].get<double>(), 4) << " |\n";
  }
  md << "\n`sheet.png`: one row per method in the order above, labelled with its name and RMSE; columns: the method's V, the "
     << "reference's V, the signed error (blue: darker than the reference, red: brighter, white: equal, saturated at |error| = "
     << kHeatRange << "; grey: background).\n";

  StagedDir dir(out_dir);
  write_text(dir.file("table.json"), table.dump(2) + "\n");
  write_text(dir.file("table.md"), md.str());
  std::vector<SheetRow> sheet_rows;
  for (std::size_t i = 0; i < images.size(); ++i) {
    const nlohmann::json& r = rows[i];
    std::vector<std::string> label = {r["method"].get<std::string>()};
    const std::string kp = key_params(r["parameters"], methods[i]->default_params());
    if (!kp.empty()) label.push_back(kp);
    label.push_back("reference: " + r["reference"]["membership"].get<std::string>());
    label.push_back("RMSE " + fixed(r["rmse"].get<double>(), 4));  // as in table.md
    sheet_rows.push_back({&images[i], &references.at(key_of(ref_falloffs[i])).visibility, &heat[i], std::move(label)});
  }
  // A missing font costs the labels, never the comparison.
  std::string font_error;
  const std::optional<Font> font = Font::open(sheet_font_path(), &font_error);
  if (!font) std::cerr << "warning: " << font_error << "; sheet.png has no labels (install fonts-dejavu-core or set AO_FONT)\n";
  write_rgb_image(dir.file("sheet.png"), contact_sheet(sheet_rows, kHeatRange, font ? &*font : nullptr));
  if (!sweep_key.empty()) {
    write_text(dir.file("sweep.json"), nlohmann::json{{"key", sweep_key}, {"rows", sweep_rows}}.dump(2) + "\n");
    std::ostringstream s;
    s << "# ao compare sweep: " << sweep_key << "\n\n| method | " << sweep_key << " | RMSE | ms |\n|---|---:|---:|---:|\n";
    for (const nlohmann::json& r : sweep_rows)
      s << "| " << r["method"].get<std::string>() << " | " << r[sweep_key].dump() << " | " << fixed(r["rmse"].get<double>(), 4) << " | "
        << fixed(r["ms"].get<double>(), 1) << " |\n";
    write_text(dir.file("sweep.md"), s.str());
  }
  dir.commit();

  if (o.json) {
    std::cout << table.dump(2) << "\n";
  } else {
    std::fprintf(stderr, "wrote %s/: table.md, table.json, sheet.png%s (R = %.4g, %s normals)\n", out_dir.string().c_str(),
                 sweep_key.empty() ? "" : ", sweep.md, sweep.json", requested.radius, o.normal.c_str());
    std::cerr << md.str().substr(md.str().find("| method"));
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
  cmd->add_option("--membership", o->falloff.membership, "Falloff mu(d) requested: " + membership_names() + " (methods may imply their own)")
      ->capture_default_str();
  cmd->add_option("-R,--radius", o->falloff.radius,
                  "Neighbourhood radius R, world units (default: --radius-fraction x the diagonal of the objects: the meshes that are not "
                  "flat, so a ground plane or walls do not change it)");
  cmd->add_option("--radius-fraction", o->falloff.radius_fraction, "R as a fraction of that diagonal")->capture_default_str();
  cmd->add_option("--normal", o->normal, std::string(kNormalHelp) + "; the same for every method and its reference")->capture_default_str();
  cmd->add_option("--tau", o->falloff.tau, "Absorption coefficient of the exp membership, 1/world units (0: 3/R)")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of the per-pixel sample sets")->capture_default_str();
  cmd->add_option("--width", o->camera.width, "Image width, pixels")->capture_default_str();
  cmd->add_option("--height", o->camera.height, "Image height, pixels")->capture_default_str();
  cmd->add_option("--fov", o->camera.fov, "Vertical field of view, degrees (default: the scene's, or 40)");
  cmd->add_option("--eye", o->camera.eye, "Camera position x,y,z (default: auto-framed)");
  cmd->add_option("--target", o->camera.target, "Point looked at x,y,z (default: the scene's centre)");
  cmd->add_option("--up", o->camera.up, "Up direction x,y,z (default: 0,1,0)");
  cmd->add_flag("--json", o->json, "Print table.json on stdout");
  cmd->footer(std::string("Environment: AO_FONT, the font file of sheet.png's labels (default ") + kDejaVuSansPath +
              "; without a readable font the sheet has no labels).");
  cmd->callback([o, &global, &action] { action = [o, &global] { return run_compare(*o, global); }; });
}

}  // namespace ao::cli
