// SPDX-License-Identifier: Apache-2.0
#include "common.h"

#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>

#include <CLI/CLI.hpp>

#include "ao/core/closest_name.h"
#include "ao/core/error.h"
#include "ao/io/json_text.h"
#include "ao/jobs/progress_meter.h"
#include "field_names.h"

namespace ao::cli {

void add_camera_options(CLI::App& cmd, CameraOptions& camera, const std::string& size_of) {
  CameraRequest& r = camera.request;
  cmd.add_option("--width", r.width, size_of + " width, pixels")->default_str(std::to_string(r.default_width));
  cmd.add_option("--height", r.height, size_of + " height, pixels")->default_str(std::to_string(r.default_height));
  cmd.add_option("--fov", r.fov, "Vertical field of view, degrees (default: the scene's, or 40)");
  cmd.add_option("--eye", camera.eye, "Camera position x,y,z (default: framing the scene from above and in front)");
  cmd.add_option("--target", camera.target, "Point looked at x,y,z (default: the scene's centre)");
  cmd.add_option("--up", camera.up, "Up direction x,y,z (default: 0,1,0)");
  cmd.add_option("--camera", r.file,
                 "Camera JSON (eye, target, up, fov, width, height; written by ao view): its view, and its size unless --width/--height are "
                 "given; the options above override its fields");
}

CameraRequest camera_request(const CameraOptions& camera) {
  CameraRequest r = camera.request;
  if (camera.eye) r.eye = parse_vec3(*camera.eye, "--eye");
  if (camera.target) r.target = parse_vec3(*camera.target, "--target");
  if (camera.up) r.up = parse_vec3(*camera.up, "--up");
  r.validate();
  return r;
}

void add_falloff_options(CLI::App& cmd, FalloffOptions& falloff, const std::string& membership_help, bool with_tau) {
  FalloffRequest& r = falloff.request;
  cmd.add_option("--membership", falloff.membership, membership_help)->capture_default_str();
  cmd.add_option("-R,--radius", r.radius,
                 "Neighbourhood radius R, world units (default: --radius-fraction x the diagonal of the objects: the meshes that are not "
                 "flat, so a ground plane or walls do not change it; with --gbuffer-in, of the visible points)");
  cmd.add_option("--radius-fraction", r.radius_fraction, "R as a fraction of that diagonal, when --radius is not given")->capture_default_str();
  if (with_tau) cmd.add_option("--tau", r.tau, "Absorption coefficient of the exp membership, 1/world units (0: 3/R)")->capture_default_str();
}

FalloffRequest falloff_request(const FalloffOptions& falloff) {
  FalloffRequest r = falloff.request;
  r.membership = membership_from_name(falloff.membership);
  r.validate();
  return r;
}

std::string param_help(const ParamSchema& schema, std::string_view name, std::string_view prefix) {
  const ParamSpec* spec = schema.find(name);
  if (!spec) throw std::logic_error("no parameter " + std::string(name) + " in the table of " + schema.owner());
  return std::string(prefix) + spec->help + " [" + spec->valid_text() + "]";
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

// A parameter file: {"parameters": {...}} (as ao tune writes) or the object itself, as key=value pairs.
std::vector<std::string> parameter_file_pairs(const std::string& path) {
  nlohmann::json j = read_json_file(path, "an object of parameters");
  if (j.is_object() && j.contains("parameters")) j = j["parameters"];
  if (!j.is_object()) throw InputError(path + ": not a JSON object of parameters");
  std::vector<std::string> pairs;
  for (const auto& [k, v] : j.items()) pairs.push_back(k + "=" + v.dump());
  return pairs;
}

namespace {

// Text of a parameter file or an option for a message: printable, at most 40 characters.
std::string shown(std::string_view text) {
  std::string out;
  for (char c : text.substr(0, 40)) out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  return text.size() > 40 ? out + "..." : out;
}

// An integer parameter gets a whole number that fits its 32-bit field, checked here before the
// method narrows it (a double beyond the int range converts to garbage); the method's own range is
// checked by its table.
nlohmann::json whole_number(const nlohmann::json& parsed, const std::string& key, const std::string& value, std::string_view method) {
  const bool whole = parsed.is_number_integer() ||
                     (parsed.is_number_float() && std::isfinite(parsed.get<double>()) && std::trunc(parsed.get<double>()) == parsed.get<double>());
  if (!whole) throw InputError("--param " + key + "=" + shown(value) + ": " + key + " of method " + std::string(method) + " is a whole number");
  const double d = parsed.get<double>();
  if (d < static_cast<double>(std::numeric_limits<int>::min()) || d > static_cast<double>(std::numeric_limits<int>::max()))
    throw InputError("--param " + key + "=" + shown(value) + ": " + key + " of method " + std::string(method) + " must be a whole number in [" +
                     std::to_string(std::numeric_limits<int>::min()) + ", " + std::to_string(std::numeric_limits<int>::max()) +
                     "] (the method's own range is narrower: see --json), got " + shown(value));
  return static_cast<std::int64_t>(d);
}

}  // namespace

void apply_param_overrides(nlohmann::json& params, const std::vector<std::string>& overrides, std::string_view method,
                           const nlohmann::json& known) {
  for (const std::string& kv : overrides) {
    if (!kv.empty() && kv[0] == '@') {
      apply_param_overrides(params, parameter_file_pairs(kv.substr(1)), method, known);
      continue;
    }
    const auto eq = kv.find('=');
    if (eq == std::string::npos || eq == 0) throw InputError("--param: expected key=value, got '" + shown(kv) + "'");
    const std::string key = kv.substr(0, eq), value = kv.substr(eq + 1);
    if (!known.contains(key)) {
      std::string names;
      for (const auto& [k, v] : known.items()) names += (names.empty() ? "" : ", ") + k;
      throw InputError("--param: method " + std::string(method) + " has no parameter '" + shown(key) + "' (it has: " + names + ")" +
                       did_you_mean(key.substr(key.find('.') + 1), names));  // "gtao.slices" (compare's form) suggests "slices"
    }
    std::optional<nlohmann::json> parsed = parse_json_limited(value, "--param " + key);
    if (known[key].is_number_integer() && parsed) parsed = whole_number(*parsed, key, value, method);
    params[key] = parsed ? std::move(*parsed) : nlohmann::json(value);
  }
}

bool stderr_is_terminal() { return isatty(STDERR_FILENO) != 0; }

struct StderrReporter::State {
  bool progress = false;
  ProgressMeter::Style style = ProgressMeter::Style::Bar;
  bool notes = true;
  std::shared_ptr<ProgressMeter> meter;
  void end() {
    if (meter) meter->close();
    meter.reset();
  }
};

StderrReporter::StderrReporter(const GlobalOptions& global, bool json) : state_(std::make_shared<State>()) {
  // A bar on a terminal; in a log (a file, CI, a farm) a line every few seconds.
  state_->progress = !global.quiet;
  state_->style = stderr_is_terminal() ? ProgressMeter::Style::Bar : ProgressMeter::Style::Log;
  state_->notes = !json;
  reporter_.stage = [s = state_](const std::string& stage) -> ProgressFn {
    s->end();
    if (!s->progress) return {};
    s->meter = std::make_shared<ProgressMeter>(stage, s->style, [](const std::string& text) {
      std::fputs(text.c_str(), stderr);
      std::fflush(stderr);
    }, log_progress_interval());
    return [meter = s->meter](std::size_t done, std::size_t total) { meter->update(done, total); };
  };
  reporter_.warning = [s = state_](const std::string& line) {
    s->end();
    std::fprintf(stderr, "warning: %s\n", in_option_words(line).c_str());
  };
  reporter_.error = [s = state_](const std::string& line) {
    s->end();
    std::fprintf(stderr, "ao: error: %s\n", in_option_words(line).c_str());
  };
  // In a log (stderr not a terminal, so no progress bars) a batch says where it is, line by line.
  if (!global.quiet && !stderr_is_terminal())
    reporter_.log = [s = state_](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
  reporter_.note = [s = state_](const std::string& line) {
    if (!s->notes) return;
    s->end();
    std::fprintf(stderr, "%s\n", in_option_words(line).c_str());
  };
}

StderrReporter::~StderrReporter() { state_->end(); }

void StderrReporter::end_stage() { state_->end(); }

namespace {
template <class T>
void declare_normal(CLI::App& cmd, T& normal, const std::string& more) {
  cmd.add_option("--normal", normal, std::string(kNormalHelp) + more)->type_name("shading|geometric")->default_str("shading");
}
}  // namespace

void add_normal_option(CLI::App& cmd, std::string& normal, const std::string& more) { declare_normal(cmd, normal, more); }
void add_normal_option(CLI::App& cmd, std::optional<std::string>& normal, const std::string& more) { declare_normal(cmd, normal, more); }

}  // namespace ao::cli
