// SPDX-License-Identifier: Apache-2.0
// Comparing AO methods with their references: the pipeline behind `ao compare`, usable without
// the command line. Each method runs through the registry on one G-buffer, is judged against the
// ray-traced reference its registry row names (or one chosen by name), and the results come back
// as rows of metrics with the images, plus error against a swept parameter, and as a Markdown /
// JSON report. Equal references are rendered once. docs/compare.md.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/membership.h"
#include "ao/core/progress.h"
#include "ao/eval/metrics.h"
#include "ao/gpu/device.h"
#include "ao/jobs/device.h"
#include "ao/jobs/inputs.h"
#include "ao/jobs/reporter.h"
#include "ao/reference/reference.h"
#include "ao/scene/analytic.h"

namespace ao {

class RayScene;

/// |signed error| at which compare's heat maps saturate, V units.
inline constexpr float kCompareHeatRange = 0.25f;

struct CompareSettings {
  std::vector<std::string> methods;  ///< Registry names; empty = every method but raytraced.
  /// Per method, parameters set over its default_params() (only keys the defaults have; others are
  /// an InputError). Methods without an entry run with their defaults.
  std::map<std::string, nlohmann::json> params;
  /// Reference per method by name (choose_reference: "matched", "obscurance", "tangent-sphere",
  /// "transfer"); the key "" applies to every method without its own entry. Default "matched".
  std::map<std::string, std::string> references;
  /// The reference every row is also judged against, so that rows can be ranked: a kind's name
  /// ("obscurance": the requested falloff's obscurance, step at R by default; "transfer";
  /// "tangent-sphere"), at the requested falloff and never at a method's own; "none" leaves the
  /// column out. A method whose matched reference is the same image shares it.
  std::string common_reference = "obscurance";
  Falloff falloff;                   ///< R and membership requested (methods may imply their own).
  int spp_reference = 256;           ///< Rays per pixel of the references, [1, 1048576].
  std::uint32_t seed = 1;            ///< Methods use it; references use seed + 1.
  std::string sweep_key;             ///< Optional: a parameter to sweep for every method that has it.
  std::vector<nlohmann::json> sweep_values;  ///< Its values (at least one when sweep_key is set).
  /// Cpu (default): the methods run on the CPU. Gpu: each method (and each swept value) also runs
  /// on the GPU backend, on the same G-buffer uploaded once, against the same reference: a column
  /// per backend. A method the GPU backend does not run is left out of the GPU column with the reason.
  Device device = Device::Cpu;
  /// Optional: called when a stage starts ("G-buffer" is the caller's; here a method's name or
  /// "reference (tangent sphere)"); the returned function receives that stage's progress.
  std::function<ProgressFn(const std::string& stage)> progress;
};

/// The rendered reference images of a comparison.
struct CompareReference {
  ReferenceSpec spec;
  Image<float> visibility;  ///< V (transfer: luminance of W).
  double ms = 0;
  double mean_std_error = 0;
};

/// A method's run on the GPU backend in a comparison (CompareSettings::device gpu): the CPU row's
/// parameters, seed and G-buffer, judged against the same reference.
struct CompareGpuRun {
  std::string skipped;              ///< Why the GPU backend did not run it (its one-line InputError); empty when it ran.
  double ms = 0;                    ///< The whole call: the passes and reading the images back (the G-buffer is on the device already).
  std::vector<GpuPassTime> passes;  ///< GPU time of each pass, in the order they ran.
  ErrorMetrics metrics;             ///< Over covered pixels, against the row's reference.
  double max_abs_difference = 0;    ///< max |V on the GPU - V on the CPU| over covered pixels.
  nlohmann::json stats;             ///< The GPU MethodOutput's stats (with "device" and "gpu_ms").
  Image<float> visibility;
  Image<Vec3> heat;                 ///< signed_error_heat_map(V, reference, coverage, kCompareHeatRange).
};

struct CompareRow {
  std::string method;
  nlohmann::json params;       ///< Complete, floats in their shortest form (shortest_floats).
  nlohmann::json defaults;     ///< The method's default_params(), to tell what was changed.
  std::size_t reference = 0;   ///< Index into CompareResult::references.
  double ms = 0;               ///< The method's run time.
  ErrorMetrics metrics;        ///< Over covered pixels.
  ErrorMetrics common;         ///< Against CompareResult::common (when it has one), over covered pixels.
  nlohmann::json stats;        ///< MethodOutput::stats.
  Image<float> visibility;     ///< The method's V.
  Image<Vec3> heat;            ///< signed_error_heat_map(V, reference, coverage, kCompareHeatRange).
  std::optional<CompareGpuRun> gpu;  ///< The same on the GPU backend (CompareSettings::device gpu).
};

struct SweepRow {
  std::string method;
  nlohmann::json value;  ///< Of CompareResult::sweep_key.
  double rmse = 0;
  double rmse_common = 0;  ///< Against CompareResult::common; 0 when there is none.
  double ms = 0;
  std::optional<CompareGpuRun> gpu;  ///< With CompareSettings::device gpu; its images are not kept.
};

struct CompareResult {
  std::vector<CompareRow> rows;          ///< In the order of CompareSettings::methods.
  std::vector<CompareReference> references;
  std::optional<std::size_t> common;     ///< Index into references of the common reference; none when "none".
  std::string sweep_key;
  std::vector<SweepRow> sweep;
  Falloff falloff;                       ///< As requested.
  int spp_reference = 0;
  std::uint32_t seed = 0;
  int width = 0, height = 0;
  Device device = Device::Cpu;  ///< Gpu: every row has its GPU run.
  std::string gl_renderer;      ///< GL_RENDERER of the GPU device; empty on the CPU.
  double gpu_upload_ms = 0;     ///< GPU time of uploading the G-buffer (once, for every row).
};

/// Everything compare_methods can check without rendering (method names, parameter keys,
/// reference names, sweep key and values, spp): InputError naming the option otherwise. Returns
/// the settings resolved: methods filled in and params complete.
CompareSettings resolve_compare_settings(const CompareSettings& settings);

/// Runs the comparison on `gbuffer` (rendered from `scene` with its camera, which carries the world
/// placement). `surfaces`: the scene's analytic description for the characteristic functions
/// (may be null). With settings.device gpu the GPU runs are on `gpu` (null: a headless device,
/// GpuDevice::open; SystemError without a usable OpenGL 4.3). Deterministic for a seed.
CompareResult compare_methods(const RayScene& scene, const GBuffer& gbuffer, const AnalyticSurfaces* surfaces, const CompareSettings& settings,
                              GpuDevice* gpu = nullptr);

/// The common reference of `settings` at the requested falloff; nullopt for "none"; InputError
/// naming --common-reference for an unknown name.
std::optional<ReferenceSpec> common_reference_spec(const CompareSettings& settings);

/// table.json's content: {"width", "height", "membership", "radius", "seed", "spp_reference",
/// "common_reference": {kind, label, membership, radius, mean_std_error, ms} (absent for "none"),
/// "rows": [{"method", "parameters", "ms", "rmse", "psnr_db", "ssim", "mean_signed_error",
/// "max_abs_error", "pixels", "reference": {kind, label, membership, radius, spp, mean_std_error,
/// ms, ...}, "common": {rmse, psnr_db, ssim, mean_signed_error, max_abs_error}, "stats"}]}; the
/// caller adds what it knows (scene, camera, timings). With the GPU backend also "device": "gpu",
/// "gl_renderer", "gpu_upload_ms", and per row "gpu": {"ms", "rmse", "psnr_db", "ssim",
/// "mean_signed_error", "max_abs_error", "pixels", "max_abs_difference_from_cpu", "passes":
/// [{"name", "ms"}], "stats"} or {"skipped": why} (judged against the row's matched reference).
nlohmann::json compare_table_json(const CompareResult& result);
/// table.md: a title line naming `scene_name`, the settings, and one row per method.
std::string compare_table_markdown(const CompareResult& result, const std::string& scene_name);
/// sweep.json's and sweep.md's content; empty sweep when no key was swept.
nlohmann::json compare_sweep_json(const CompareResult& result);
std::string compare_sweep_markdown(const CompareResult& result);

/// The parameters a reader needs to tell rows apart: the sample count and quality preset where a
/// method has them, and whatever differs from the defaults; empty when longer than `max_chars`.
std::string compare_key_params(const CompareRow& row, std::size_t max_chars = 40);

// ---- `ao compare` as a library call: a scene in, the comparison and its files out.

struct CompareRequest {
  SceneSource scene;
  CameraRequest camera = CameraRequest::sized(640, 360);
  FalloffRequest falloff;
  SurfaceNormal normal = SurfaceNormal::Shading;  ///< The G-buffer's N, for every method and its reference.
  CompareSettings settings;   ///< Methods, parameters, references, spp, seed, sweep (falloff and progress are set by the job).
  /// Where table.json, table.md, sheet.png (and sweep.json, sweep.md) go; created when missing.
  /// Empty: nothing is written.
  std::filesystem::path out_dir;
  std::filesystem::path font;  ///< The sheet's label font; empty: DejaVu Sans where Debian installs it.
};

struct CompareJobResult {
  CompareResult result;
  std::string scene;          ///< Its name.
  Camera camera;
  nlohmann::json table;       ///< table.json, with the scene, camera and setup time.
  std::string markdown;       ///< table.md.
  Image<Vec3> sheet;          ///< sheet.png: per row the method, its reference and the error heat map.
  std::vector<std::filesystem::path> written;
};

/// compare-<scene stem>: where `ao compare` writes without --out-dir.
std::filesystem::path default_compare_dir(const CompareRequest& request);

/// Renders the G-buffer of `request`'s scene and camera, runs compare_methods, and writes the
/// files into out_dir as one transaction (refused before any work when one names an input). The
/// checks that need no scene (methods, parameters, references, camera, falloff) come first.
/// Problems methods worked around (cone: open meshes) are reported as warnings.
CompareJobResult run_compare(const CompareRequest& request, const JobReporter& reporter = {});

/// `j` with every number that is exactly a float replaced by the double of its shortest decimal
/// form (0.0001f, stored as 9.999999747378752e-05, becomes 0.0001), so JSON and tables print
/// floats at the precision they were given. Recursive over objects and arrays.
nlohmann::json shortest_floats(const nlohmann::json& j);
/// A number in its shortest round-trip form (floats that are exactly floats as floats); strings
/// unquoted; other JSON as dumped.
std::string format_value(const nlohmann::json& v);

}  // namespace ao
