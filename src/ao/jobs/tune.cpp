// SPDX-License-Identifier: Apache-2.0
#include "ao/jobs/tune.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>

#include "ao/core/closest_name.h"
#include "ao/core/error.h"
#include "ao/jobs/fields.h"
#include "ao/jobs/provenance.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/io/atomic_file.h"
#include "ao/io/output_set.h"
#include "ao/reference/ray_scene.h"
#include "ao/reference/reference.h"
#include "ao/jobs/compare.h"
#include "ao/eval/metrics.h"
#include "ao/registry/registry.h"

namespace ao {

namespace {

// The parameter whose 0 means "the falloff radius R" (Alchemy's r).
constexpr std::string_view kRadiusParam = "radius";

// The views' falloff radius R (their mean: each scene chooses its own).
double mean_radius(const std::vector<TuneView>& views) {
  double sum = 0;
  for (const TuneView& v : views) sum += v.falloff.radius;
  return sum / static_cast<double>(views.size());
}

// The search's start: the method's defaults (or the given start), each fitted parameter a number
// inside its range (integer where the parameter is).
nlohmann::json tune_start(const MethodInfo& m, const TuneSettings& s, const std::vector<TuneView>& views) {
  nlohmann::json current = s.start.is_null() ? m.default_params() : s.start;
  // A value a preset leaves unset starts where the method has it (Alchemy's intensity 0.4 at the
  // fitted preset), so the start does not depend on the range asked for.
  const nlohmann::json resolved = params_json(with_presets_resolved(m.decode(current)));
  for (const TuneParameter& p : s.parameters) {
    if (!current.contains(p.key)) throw InputError("tune: method " + s.method + " has no parameter '" + p.key + "'" + did_you_mean(p.key, key_names(current)));
    if (!(p.lo < p.hi) || !std::isfinite(p.lo) || !std::isfinite(p.hi))
      throw InputError("tune: the range of '" + p.key + "' must be finite with lo < hi");
    if (current.at(p.key).is_null()) current[p.key] = resolved.value(p.key, nlohmann::json());
    if (current.at(p.key).is_null()) current[p.key] = 0.5 * (p.lo + p.hi);  // no preset gives it a value
    if (!current.at(p.key).is_number()) throw InputError("tune: parameter '" + p.key + "' of " + s.method + " is not a number");
    // A radius at 0 runs at the views' R: the search starts there, not at the range's end.
    if (p.key == kRadiusParam && current.at(p.key).get<double>() == 0) current[p.key] = shortest_floats(nlohmann::json(static_cast<float>(mean_radius(views))));
    // A start outside the range begins at its nearest end.
    const double x = current.at(p.key).get<double>();
    if (x < p.lo || x > p.hi) current[p.key] = shortest_floats(nlohmann::json(static_cast<float>(std::clamp(x, p.lo, p.hi))));
    if (p.integer) current[p.key] = static_cast<long long>(std::llround(current.at(p.key).get<double>()));
  }
  return current;
}

nlohmann::json tune_value(const TuneParameter& p, double x) {
  x = std::clamp(x, p.lo, p.hi);
  return p.integer ? nlohmann::json(static_cast<long long>(std::llround(x))) : shortest_floats(nlohmann::json(static_cast<float>(x)));
}

// Coordinate search from `current` (error `best`): each parameter in turn steps a quarter of its
// range up, else down, keeping the first move that lowers the error and halving its step when
// neither does; until every step is below min_step of its range (half a unit for integers) or the
// time is up. Leaves the best point in `current` and returns its error.
double coordinate_search(const TuneSettings& s, nlohmann::json& current, double best,
                         const std::function<double(const nlohmann::json&)>& evaluate, const std::function<double()>& seconds) {
  std::vector<double> step;
  for (const TuneParameter& p : s.parameters) step.push_back((p.hi - p.lo) / 4);
  bool moving = true;
  while (moving && seconds() < s.time_budget_s) {
    moving = false;
    for (std::size_t i = 0; i < s.parameters.size() && seconds() < s.time_budget_s; ++i) {
      const TuneParameter& p = s.parameters[i];
      if (step[i] < s.min_step * (p.hi - p.lo) || (p.integer && step[i] < 0.5)) continue;
      moving = true;
      const double x = current.at(p.key).get<double>();
      bool improved = false;
      for (double sign : {1.0, -1.0}) {
        nlohmann::json trial = current;
        trial[p.key] = tune_value(p, x + sign * step[i]);
        if (trial[p.key] == current[p.key]) continue;
        const double e = evaluate(trial);
        if (e < best) {
          best = e;
          current = std::move(trial);
          improved = true;
          if (s.log) s.log(p.key + " = " + format_value(current[p.key]) + ": mean RMSE " + std::to_string(best));
          break;
        }
      }
      if (!improved) step[i] /= 2;
    }
  }
  return best;
}

}  // namespace

TuneResult tune_method(const std::vector<TuneView>& views, const TuneSettings& s) {
  const auto start_time = std::chrono::steady_clock::now();
  const auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count(); };
  const MethodInfo& m = find_method(s.method);
  if (views.empty()) throw InputError("tune: no view to fit on");
  if (s.parameters.empty()) throw InputError("tune: no parameter to fit");
  if (!(s.time_budget_s > 0)) throw InputError("tune: the time budget must be > 0 seconds");
  if (!(s.min_step > 0 && s.min_step < 1)) throw InputError("tune: min_step must be in (0, 1)");
  nlohmann::json current = tune_start(m, s, views);

  TuneResult r;
  // Mean RMSE over the views; a parameter value the method refuses counts as infinitely bad.
  std::vector<Image<std::uint8_t>> covered;
  for (const TuneView& v : views) covered.push_back(coverage_mask(*v.gbuffer));
  auto evaluate = [&](const nlohmann::json& params) {
    ++r.evaluations;
    double sum = 0;
    for (std::size_t i = 0; i < views.size(); ++i) {
      const TuneView& v = views[i];
      MethodOutput out;
      try {
        out = run_method(MethodInput{*v.gbuffer, v.scene, v.falloff, s.seed, {}, v.surfaces}, m.decode(params));
      } catch (const InputError&) {
        return std::numeric_limits<double>::infinity();
      }
      sum += compare_images(out.visibility, v.reference, covered[i]).rmse;
    }
    return sum / static_cast<double>(views.size());
  };

  r.start_rmse = evaluate(current);
  r.best_rmse = coordinate_search(s, current, r.start_rmse, evaluate, seconds);
  r.params = shortest_floats(current);
  for (const TuneParameter& p : s.parameters) {
    const double x = r.params.at(p.key).get<double>();
    if (x <= p.lo || x >= p.hi) r.on_bound.push_back(p.key);
  }
  r.seconds = seconds();
  return r;
}

}  // namespace ao

// ---- The tune job.

namespace ao {

namespace {

std::string number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// The parameter file as render's outputs are checked, before any work: a .json name that names
// none of the files the run reads (its scenes, camera file, parameter files) and no folder.
void declare_output(const TuneRequest& r, OutputSet& outputs) {
  if (r.output.empty()) return;
  std::string ext = r.output.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".json") throw InputError(r.output.string() + ": " + field(fields::kTuneOutput) + " is the parameter file, written as JSON; give it a .json name");
  for (const std::string& scene : r.scenes) SceneSource{.args = {scene}}.declare_inputs(outputs);
  if (r.camera.file) outputs.add_input(*r.camera.file, "--camera");
  for (const std::filesystem::path& p : r.parameter_files) outputs.add_input(p, "-p @" + p.string());
  outputs.add_output(r.output, field(fields::kTuneOutput));
}

}  // namespace

std::vector<TuneParameter> tune_parameters(const MethodInfo& m, const std::vector<TuneFit>& fit) {
  if (fit.empty()) throw InputError(field(fields::kTuneFit) + ": name at least one parameter to fit (key or key=lo:hi)");
  std::vector<TuneParameter> out;
  for (const TuneFit& f : fit) {
    const ParamSpec* spec = m.params().find(f.key);
    if (!spec)
      throw InputError(field(fields::kTuneFit) + ": method " + std::string(m.name) + " has no parameter '" + f.key + "'" +
                       did_you_mean(f.key, key_names(m.default_params())));
    const bool integer = spec->type == ParamType::Int || spec->type == ParamType::OptionalInt;
    if (!integer && spec->type != ParamType::Float && spec->type != ParamType::OptionalFloat)
      throw InputError(field(fields::kTuneFit) + ": '" + f.key + "' of " + std::string(m.name) + " is " + spec->valid_text() + ", not a number to fit");
    const Range& valid = spec->range;
    TuneParameter p{.key = f.key, .lo = f.lo.value_or(valid.min), .hi = f.hi.value_or(valid.max), .integer = integer};
    if (!f.lo && (valid.min_open || !std::isfinite(valid.min)))
      throw InputError(field(fields::kTuneFit) + ": '" + f.key + "' is " + spec->valid_text() + ": give its range as " + f.key + "=lo:hi");
    if (!f.hi && (valid.max_open || !std::isfinite(valid.max)))
      throw InputError(field(fields::kTuneFit) + ": '" + f.key + "' is " + spec->valid_text() + ": give its range as " + f.key + "=lo:hi");
    if (!(p.lo < p.hi) || !std::isfinite(p.lo) || !std::isfinite(p.hi))
      throw InputError(field(fields::kTuneFit) + ": the range of '" + f.key + "' must be finite with lo < hi, got " + number(p.lo) + ":" + number(p.hi));
    if (!valid.contains(p.lo) || !valid.contains(p.hi))
      throw InputError(field(fields::kTuneFit) + ": the range " + number(p.lo) + ":" + number(p.hi) + " of '" + f.key + "' leaves its valid values, " + spec->valid_text());
    out.push_back(p);
  }
  return out;
}

TuneJobResult run_tune(const TuneRequest& r, const JobReporter& reporter) {
  const MethodInfo& m = find_method(r.method);
  nlohmann::json start = r.params;
  start = m.canonical_params(start);
  TuneSettings settings{.method = r.method, .start = start, .time_budget_s = r.budget_s, .seed = r.seed};
  settings.parameters = tune_parameters(m, r.fit);
  if (r.spp_reference < 1 || r.spp_reference > (1 << 20)) throw InputError(field(fields::kTuneSppReference) + " must be in [1, 1048576], got " + std::to_string(r.spp_reference));
  if (r.scenes.empty()) throw InputError(field(fields::kTuneScenes) + ": no scene named");
  r.camera.validate();
  r.falloff.validate();
  OutputSet outputs;
  declare_output(r, outputs);

  // Each view keeps its scene, BVH and G-buffer alive while tuning runs.
  struct Loaded {
    std::unique_ptr<PreparedScene> scene;
    GBuffer g;
  };
  std::vector<std::unique_ptr<Loaded>> loaded;
  std::vector<TuneView> views;
  for (const std::string& name : r.scenes) {
    auto l = std::make_unique<Loaded>();
    l->scene = std::make_unique<PreparedScene>(SceneSource{.args = {name}}.load(), "ao tune", BvhOptions{});
    const Scene& scene = *l->scene->scene;
    l->g = render_gbuffer(*l->scene->rays, choose_camera(scene, r.camera), GBufferOptions{.normal = r.normal});
    const Falloff f = choose_falloff(r.falloff, interest_diagonal(scene));  // R as ao render and ao compare choose it
    Image<float> ref = render_reference(*l->scene->rays, l->g, matched_reference(f, m.decode(start)), {.samples = r.spp_reference}, r.seed + 1,
                                        reporter.start("reference (" + name + ")"))
                           .scalar.visibility;
    views.push_back({l->scene->rays.get(), &l->g, &scene.analytic, f, std::move(ref)});
    loaded.push_back(std::move(l));
  }
  settings.log = reporter.note;
  TuneJobResult out;
  out.tune = tune_method(views, settings);
  for (const std::string& key : out.tune.on_bound) {
    const TuneParameter& p = *std::find_if(settings.parameters.begin(), settings.parameters.end(), [&](const TuneParameter& q) { return q.key == key; });
    const bool low = out.tune.params.at(key).get<double>() <= p.lo;
    reporter.warn(key + " = " + format_value(out.tune.params.at(key)) + " is the " + (low ? "lower" : "upper") + " end of its range " + number(p.lo) +
                  ":" + number(p.hi) + "; the best value may lie beyond it: widen " + field(fields::kTuneFit) + " " + key + "=lo:hi if the parameter's valid range allows");
  }
  const int width = r.camera.width.value_or(r.camera.default_width), height = r.camera.height.value_or(r.camera.default_height);
  out.file = {{"ao", build_info()},       {"method", r.method},       {"parameters", out.tune.params}, {"start_rmse", out.tune.start_rmse}, {"best_rmse", out.tune.best_rmse},
              {"evaluations", out.tune.evaluations}, {"seconds", out.tune.seconds}, {"scenes", r.scenes},
              {"width", width},           {"height", height}, {"on_bound", out.tune.on_bound}};
  if (!r.output.empty()) {
    outputs.write(r.output, [&] { write_bytes_atomically(r.output, out.file.dump(2) + "\n"); });
    outputs.commit();
  }
  return out;
}

}  // namespace ao
