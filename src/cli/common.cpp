#include "common.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <sstream>

#include <CLI/CLI.hpp>

#include "ao/core/error.h"
#include "ao/io/camera_json.h"
#include "ao/io/mesh_io.h"
#include "ao/scene/procedural.h"

namespace ao::cli {

namespace {
// A lone word that is not a file names a built-in scene (an unknown one gets the list of names).
bool names_builtin_scene(const std::vector<std::string>& args) {
  if (args.size() != 1) return false;
  const std::filesystem::path first(args[0]);
  return !std::filesystem::exists(first) && !first.has_extension();
}
}  // namespace

void add_camera_options(CLI::App& cmd, CameraOptions& camera, const std::string& size_of) {
  cmd.add_option("--width", camera.width, size_of + " width, pixels")->capture_default_str();
  cmd.add_option("--height", camera.height, size_of + " height, pixels")->capture_default_str();
  cmd.add_option("--fov", camera.fov, "Vertical field of view, degrees (default: the scene's, or 40)");
  cmd.add_option("--eye", camera.eye, "Camera position x,y,z (default: framing the scene from above and in front)");
  cmd.add_option("--target", camera.target, "Point looked at x,y,z (default: the scene's centre)");
  cmd.add_option("--up", camera.up, "Up direction x,y,z (default: 0,1,0)");
  cmd.add_option("--camera", camera.file,
                 "Camera JSON (eye, target, up, fov, width, height; written by ao view): its view, and its size unless --width/--height are "
                 "given; the options above override its fields");
}

void note_camera_size_given(const CLI::App& cmd, CameraOptions& camera) {
  camera.width_set = cmd.get_option("--width")->count() > 0;
  camera.height_set = cmd.get_option("--height")->count() > 0;
}

std::string scene_arguments_name(const std::vector<std::string>& args) {
  if (args.empty()) return "default";
  if (names_builtin_scene(args)) return args[0];
  std::string name;
  for (const std::string& a : args) {
    if (!name.empty()) name += '+';
    name += std::filesystem::path(a).filename().string();
  }
  return name;
}

void add_scene_inputs(OutputSet& outputs, const std::vector<std::string>& args) {
  if (args.empty() || names_builtin_scene(args)) return;
  for (const std::string& a : args) outputs.add_input(a, "the scene " + a);
}

Scene load_scene_arguments(const std::vector<std::string>& args) {
  if (args.empty()) return make_builtin_scene("default");
  if (names_builtin_scene(args)) return make_builtin_scene(args[0]);
  Scene merged;
  for (const std::string& a : args) {
    Scene s = load_scene_file(a);
    merged.name += (merged.name.empty() ? "" : "+") + s.name;
    const auto first_mesh = static_cast<std::uint32_t>(merged.meshes.size());
    for (Instance& in : s.instances) {
      in.mesh += first_mesh;
      merged.instances.push_back(std::move(in));
    }
    for (Mesh& m : s.meshes) merged.meshes.push_back(std::move(m));
    for (std::string& w : s.warnings) merged.warnings.push_back(std::move(w));
  }
  return merged;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, sep))
    if (!item.empty()) out.push_back(item);
  return out;
}

Vec3 parse_vec3(const std::string& text, const char* option) {
  std::istringstream in(text);
  Vec3 v;
  char c1 = 0, c2 = 0;
  if (!(in >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof() || !is_finite(v))
    throw InputError(std::string(option) + ": expected three finite numbers as x,y,z, got '" + text + "'");
  return v;
}

// Mirrors Camera::validate's limits (camera.cpp), checked here before any file is read and with
// the option's name.
constexpr int kMaxImageSide = 32768;

void check_camera_options(const CameraOptions& opt, bool size_given) {
  if (size_given) {
    if (opt.width < 1 || opt.width > kMaxImageSide)
      throw InputError("--width must be in [1, " + std::to_string(kMaxImageSide) + "] pixels, got " + std::to_string(opt.width));
    if (opt.height < 1 || opt.height > kMaxImageSide)
      throw InputError("--height must be in [1, " + std::to_string(kMaxImageSide) + "] pixels, got " + std::to_string(opt.height));
  }
  if (opt.fov && !(*opt.fov > 0.0f && *opt.fov < 180.0f)) {
    std::ostringstream v;
    v << *opt.fov;
    throw InputError("--fov must be in (0, 180) degrees, got " + v.str());
  }
  if (opt.eye) parse_vec3(*opt.eye, "--eye");
  if (opt.target) parse_vec3(*opt.target, "--target");
  if (opt.up) parse_vec3(*opt.up, "--up");
}

void check_falloff_options(const FalloffOptions& opt) {
  const auto m = parse_membership(opt.membership);
  if (!m) throw InputError("--membership: unknown '" + opt.membership + "' (known: " + membership_names() + ")");
  if (opt.radius && !(*opt.radius > 0.0f && std::isfinite(*opt.radius)))
    throw InputError("--radius must be a positive finite number of world units, got " + std::to_string(*opt.radius));
  if (!opt.radius && !(opt.radius_fraction > 0.0f && opt.radius_fraction <= 10.0f))
    throw InputError("--radius-fraction must be in (0, 10], got " + std::to_string(opt.radius_fraction));
  if (!(opt.tau >= 0.0f && std::isfinite(opt.tau))) throw InputError("--tau must be >= 0 (0 selects 3/R), got " + std::to_string(opt.tau));
}

Camera choose_camera(const Scene& scene, const CameraOptions& opt) {
  check_camera_options(opt);
  Camera cam;
  if (opt.file) {
    Camera defaults;
    defaults.width = opt.width;
    defaults.height = opt.height;
    cam = read_camera_file(*opt.file, defaults);
    if (opt.width_set) cam.width = opt.width;
    if (opt.height_set) cam.height = opt.height;
  } else if (scene.preferred_view) {
    cam = *scene.preferred_view;
  } else {
    // Auto-framing: from the front, a little to the right and above, the usual product shot.
    cam = frame_bounds(scene.bounds(), {0.55f, 0.5f, 1.0f}, opt.fov.value_or(40.0f), opt.width, opt.height);
  }
  if (!opt.file) {
    cam.width = opt.width;
    cam.height = opt.height;
  }
  if (opt.fov) cam.vertical_fov_deg = *opt.fov;
  if (opt.up) cam.up = parse_vec3(*opt.up, "--up");
  if (opt.target) cam.target = parse_vec3(*opt.target, "--target");
  if (opt.eye) {
    cam.eye = parse_vec3(*opt.eye, "--eye");
  } else if (opt.target && !scene.preferred_view && !opt.file) {
    // Keep the framing distance and direction, looking at the new target.
    const Camera framed = frame_bounds(scene.bounds(), {0.55f, 0.5f, 1.0f}, cam.vertical_fov_deg, cam.width, cam.height);
    cam.eye = cam.target + (framed.eye - framed.target);
  }
  cam.validate();
  return cam;
}

namespace {

// Every vertex within 1e-5 of the mesh's diagonal from the plane of its largest triangle.
bool is_flat(const Mesh& m) {
  float best = -1;
  Vec3 n{0, 0, 0}, origin{0, 0, 0};
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const Vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]], c = m.positions[m.indices[3 * t + 2]];
    const Vec3 cr = cross(b - a, c - a);
    const float area2 = length(cr);
    if (area2 > best) best = area2, n = cr / area2, origin = a;
  }
  if (!(best > 0)) return true;
  const float tolerance = 1e-5f * m.bounds().diagonal();
  for (const Vec3& p : m.positions)
    if (std::abs(dot(p - origin, n)) > tolerance) return false;
  return true;
}

}  // namespace

float interest_diagonal(const Scene& scene) {
  Bounds3 objects;
  for (const SceneObject& o : scene.objects()) {
    const Mesh& m = scene.meshes[o.mesh];
    if (is_flat(m)) continue;  // flatness survives an affine map
    objects.extend(o.instance == SceneObject::kNoInstance ? m.bounds() : transform_bounds(scene.instances[o.instance].object_to_world, m.bounds()));
  }
  return objects.empty() ? scene.bounds().diagonal() : objects.diagonal();
}

SurfaceNormal parse_surface_normal(const std::string& text) {
  if (text == "shading") return SurfaceNormal::Shading;
  if (text == "geometric") return SurfaceNormal::Geometric;
  throw InputError("--normal: expected shading or geometric, got '" + text + "'");
}

Falloff choose_falloff(const FalloffOptions& opt, float scene_diagonal) {
  const auto m = parse_membership(opt.membership);
  if (!m) throw InputError("--membership: unknown '" + opt.membership + "' (known: " + membership_names() + ")");
  if (!opt.radius && !(opt.radius_fraction > 0.0f && opt.radius_fraction <= 10.0f))
    throw InputError("--radius-fraction must be in (0, 10]");
  Falloff f{*m, opt.radius ? *opt.radius : opt.radius_fraction * scene_diagonal, opt.tau};
  f.validate();
  return f;
}

bool stderr_is_terminal() { return isatty(STDERR_FILENO) != 0; }

struct ProgressBar::State {
  std::string label;
  bool enabled;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last_draw{};
  std::mutex mutex;
  bool drawn = false;
};

ProgressBar::ProgressBar(std::string label, bool enabled) : state_(std::make_shared<State>()) {
  state_->label = std::move(label);
  state_->enabled = enabled;
}

ProgressBar::~ProgressBar() {
  if (state_->drawn) std::fputs("\r\033[K", stderr);
}

ProgressFn ProgressBar::callback() {
  if (!state_->enabled) return {};
  return [s = state_](std::size_t done, std::size_t total) {
    const auto now = std::chrono::steady_clock::now();
    if (now - s->start < std::chrono::seconds(1)) return;
    std::unique_lock lock(s->mutex, std::try_to_lock);
    if (!lock.owns_lock() || now - s->last_draw < std::chrono::milliseconds(100)) return;
    s->last_draw = now;
    s->drawn = true;
    const double f = total > 0 ? static_cast<double>(done) / static_cast<double>(total) : 1.0;
    const double elapsed = std::chrono::duration<double>(now - s->start).count();
    const int width = 30, filled = static_cast<int>(f * width);
    std::fprintf(stderr, "\r%s [%s%s] %3d%%  %.1fs, ~%.0fs left\033[K", s->label.c_str(), std::string(filled, '#').c_str(),
                 std::string(width - filled, '.').c_str(), static_cast<int>(f * 100), elapsed, f > 0 ? elapsed * (1 - f) / f : 0.0);
    std::fflush(stderr);
  };
}

double Stopwatch::lap_ms() {
  const auto now = std::chrono::steady_clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - start_).count();
  start_ = now;
  return ms;
}

void apply_param_overrides(nlohmann::json& params, const std::vector<std::string>& overrides, std::string_view method) {
  for (const std::string& kv : overrides) {
    if (!kv.empty() && kv[0] == '@') {  // a parameter file: {"parameters": {...}} (as ao tune writes) or the object itself
      const std::string path = kv.substr(1);
      std::ifstream in(path);
      if (!in) throw InputError(path + ": cannot open the parameter file");
      nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
      if (j.is_object() && j.contains("parameters")) j = j["parameters"];
      if (!j.is_object()) throw InputError(path + ": not a JSON object of parameters");
      std::vector<std::string> pairs;
      for (const auto& [k, v] : j.items()) pairs.push_back(k + "=" + v.dump());
      apply_param_overrides(params, pairs, method);
      continue;
    }
    const auto eq = kv.find('=');
    if (eq == std::string::npos || eq == 0) throw InputError("--param: expected key=value, got '" + kv + "'");
    const std::string key = kv.substr(0, eq), value = kv.substr(eq + 1);
    if (!params.contains(key)) {
      std::string known;
      for (const auto& [k, v] : params.items()) known += (known.empty() ? "" : ", ") + k;
      throw InputError("--param: method " + std::string(method) + " has no parameter '" + key + "' (it has: " + known + ")");
    }
    nlohmann::json parsed = nlohmann::json::parse(value, nullptr, /*allow_exceptions=*/false);
    // An integer parameter gets a whole number that fits its 32-bit field, checked here before
    // the method narrows it (a double beyond the int range converts to garbage); the method's
    // own range is checked by its validate().
    if (params[key].is_number_integer() && !parsed.is_discarded()) {
      const bool whole = parsed.is_number_integer() || (parsed.is_number_float() && std::isfinite(parsed.get<double>()) &&
                                                        std::trunc(parsed.get<double>()) == parsed.get<double>());
      if (!whole) throw InputError("--param " + key + "=" + value + ": " + key + " of method " + std::string(method) + " is a whole number");
      const double d = parsed.get<double>();
      if (d < static_cast<double>(std::numeric_limits<int>::min()) || d > static_cast<double>(std::numeric_limits<int>::max()))
        throw InputError("--param " + key + "=" + value + ": " + key + " of method " + std::string(method) + " must be a whole number in [" +
                         std::to_string(std::numeric_limits<int>::min()) + ", " + std::to_string(std::numeric_limits<int>::max()) +
                         "] (the method's own range is narrower: see --json), got " + value);
      parsed = static_cast<std::int64_t>(d);
    }
    params[key] = parsed.is_discarded() ? nlohmann::json(value) : parsed;
  }
}

nlohmann::json to_json(Vec3 v) { return nlohmann::json::array({v.x, v.y, v.z}); }

nlohmann::json to_json(const Camera& c) {
  return {{"eye", to_json(c.eye)}, {"target", to_json(c.target)}, {"up", to_json(c.up)}, {"fov", c.vertical_fov_deg}};
}

}  // namespace ao::cli
