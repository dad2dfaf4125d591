// SPDX-License-Identifier: Apache-2.0
// Fitting a method's numeric parameters to its reference: coordinate descent on the mean RMSE over
// a set of views (scenes and cameras), each judged against the method's matched reference, within
// a time budget. The references are rendered once per view; each evaluation runs the method on
// every view. `ao tune` is its command-line shell (docs/compare.md#ao-tune).
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/membership.h"
#include "ao/jobs/inputs.h"
#include "ao/jobs/reporter.h"
#include "ao/scene/analytic.h"

namespace ao {

class RayScene;
struct MethodInfo;

/// One parameter to fit, within [lo, hi]; integer parameters take rounded values.
struct TuneParameter {
  std::string key;
  double lo = 0, hi = 1;
  bool integer = false;
};

/// One view to fit on: the scene (for object-space methods), its G-buffer, its analytic surfaces
/// (may be null), the requested falloff, and the reference image (render it with render_reference
/// of the method's MethodInfo::reference for the starting parameters: it stays fixed while the
/// parameters move, also where the matched reference depends on them, as Alchemy's falloff does).
struct TuneView {
  const RayScene* scene = nullptr;
  const GBuffer* gbuffer = nullptr;
  const AnalyticSurfaces* surfaces = nullptr;
  Falloff falloff;
  Image<float> reference;
};

struct TuneSettings {
  std::string method;                    ///< Registry name.
  /// Complete parameters to start from (default_params() when null). A fitted value left null
  /// starts where the method's preset puts it (with_presets_resolved, registry.h), else mid-range; a
  /// `radius` at 0 (the falloff radius R, Alchemy's r) at the views' mean R; a start outside
  /// [lo, hi] at its nearest end.
  nlohmann::json start;
  std::vector<TuneParameter> parameters; ///< At least one; keys the method has, numeric values.
  double time_budget_s = 60;             ///< Stops after the first evaluation past this, seconds, > 0.
  double min_step = 1e-3;                ///< Stops when every step is below this fraction of its range, (0, 1).
  std::uint32_t seed = 1;
  std::function<void(const std::string&)> log;  ///< Optional: one line per accepted improvement.
};

struct TuneResult {
  nlohmann::json params;     ///< The best parameters found (complete; floats in shortest form).
  double start_rmse = 0;     ///< Mean RMSE over the views at the start.
  double best_rmse = 0;      ///< At `params`.
  int evaluations = 0;       ///< Method runs over all views.
  /// The fitted parameters that ended at an end of their range: the best value may lie beyond it.
  std::vector<std::string> on_bound;
  double seconds = 0;
};

/// Coordinate descent: for each parameter in turn, try the current value plus and minus its step
/// (a quarter of its range at first, clamped to [lo, hi]); keep a move that lowers the mean RMSE,
/// else halve that parameter's step. Deterministic for a seed (the methods are). InputError for
/// unknown methods or keys, non-numeric values, empty ranges or an empty view list.
TuneResult tune_method(const std::vector<TuneView>& views, const TuneSettings& settings);

// ---- `ao tune` as a library call: scenes and a method in, fitted parameters (and their file) out.

/// A parameter to fit: its name, and optionally its range (default: the parameter table's range,
/// which must then be finite and closed). Integer-ness comes from the table.
struct TuneFit {
  std::string key;
  std::optional<double> lo, hi;
};

struct TuneRequest {
  std::vector<std::string> scenes = {"default"};  ///< One view each: built-in names or mesh files.
  std::string method;
  std::vector<TuneFit> fit;                        ///< At least one.
  nlohmann::json params = nlohmann::json::object();  ///< Overrides of the defaults: the starting point.
  double budget_s = 60;                            ///< Seconds, > 0.
  int spp_reference = 256;                         ///< Rays per pixel of the references, [1, 1048576].
  CameraRequest camera = CameraRequest::sized(320, 180);
  FalloffRequest falloff;
  SurfaceNormal normal = SurfaceNormal::Shading;  ///< The G-buffer's N, for the method and its reference.
  std::uint32_t seed = 1;
  std::filesystem::path output;                    ///< The parameter file (.json; `ao render -p @FILE`); empty: not written.
  /// Files the starting parameters were read from (`-p @FILE`): `output` may not name one.
  std::vector<std::filesystem::path> parameter_files;
};

struct TuneJobResult {
  TuneResult tune;
  nlohmann::json file;  ///< What the parameter file holds.
};

/// The parameters to fit, each with its range and integer-ness from the method's table;
/// InputError naming --fit for an unknown or non-numeric key or a range that is empty, infinite or
/// outside the parameter's valid range.
std::vector<TuneParameter> tune_parameters(const MethodInfo& method, const std::vector<TuneFit>& fit);

/// Loads each scene, renders its G-buffer and its matched reference (for the starting
/// parameters), runs tune_method and writes the parameter file. Each accepted improvement is told
/// to the reporter as a note. Before any work, InputError when `output` does not end in .json or
/// names a scene file, the camera file, a parameter file or a folder (as render's outputs).
TuneJobResult run_tune(const TuneRequest& request, const JobReporter& reporter = {});

}  // namespace ao
