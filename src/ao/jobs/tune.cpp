#include "ao/jobs/tune.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "ao/core/error.h"
#include "ao/jobs/compare.h"
#include "ao/eval/metrics.h"
#include "ao/registry/registry.h"

namespace ao {

TuneResult tune_method(const std::vector<TuneView>& views, const TuneSettings& s) {
  const auto start_time = std::chrono::steady_clock::now();
  const auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count(); };
  const MethodInfo& m = find_method(s.method);
  if (views.empty()) throw InputError("tune: no view to fit on");
  if (s.parameters.empty()) throw InputError("tune: no parameter to fit");
  if (!(s.time_budget_s > 0)) throw InputError("tune: the time budget must be > 0 seconds");
  if (!(s.min_step > 0 && s.min_step < 1)) throw InputError("tune: min_step must be in (0, 1)");
  nlohmann::json current = s.start.is_null() ? m.default_params() : s.start;
  for (const TuneParameter& p : s.parameters) {
    if (!current.contains(p.key)) throw InputError("tune: method " + s.method + " has no parameter '" + p.key + "'");
    // An optional number left unset ("the preset's value") starts at the middle of its range.
    if (current.at(p.key).is_null()) current[p.key] = 0.5 * (p.lo + p.hi);
    if (!current.at(p.key).is_number()) throw InputError("tune: parameter '" + p.key + "' of " + s.method + " is not a number");
    if (!(p.lo < p.hi) || !std::isfinite(p.lo) || !std::isfinite(p.hi))
      throw InputError("tune: the range of '" + p.key + "' must be finite with lo < hi");
  }

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
        out = m.run(MethodInput{*v.gbuffer, v.scene, v.falloff, s.seed, {}, v.surfaces}, params);
      } catch (const InputError&) {
        return std::numeric_limits<double>::infinity();
      }
      sum += compare_images(out.visibility, v.reference, covered[i]).rmse;
    }
    return sum / static_cast<double>(views.size());
  };
  auto value_of = [](const TuneParameter& p, double x) {
    x = std::clamp(x, p.lo, p.hi);
    return p.integer ? nlohmann::json(static_cast<long long>(std::llround(x))) : shortest_floats(nlohmann::json(static_cast<float>(x)));
  };

  double best = evaluate(current);
  r.start_rmse = best;
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
        trial[p.key] = value_of(p, x + sign * step[i]);
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
  r.params = shortest_floats(current);
  r.best_rmse = best;
  r.seconds = seconds();
  return r;
}

}  // namespace ao
