// SPDX-License-Identifier: Apache-2.0
// What every subcommand shares: the options that fill the job layer's scene, camera and falloff
// requests, the key=value method parameters, and the reporter that prints a job's progress,
// warnings and notes on stderr.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/params.h"
#include "ao/jobs/inputs.h"
#include "ao/jobs/reporter.h"

namespace CLI {
class App;
}

namespace ao::cli {

/// Options of `ao` itself, before the subcommand.
struct GlobalOptions {
  int threads = 0;     ///< Worker threads; 0 = all cores.
  bool quiet = false;  ///< No progress (bar or log lines).
  /// Stop once the command line is turned into the job's request, before any scene is read or
  /// work done: the option parser's fuzzing harness (fuzz/fuzz_options.cpp) sets it.
  bool request_only = false;
};

/// Help text of the positional scene argument, shared by the subcommands that take a scene.
inline constexpr const char* kSceneHelp =
    "Mesh file(s) (OBJ, PLY, OFF, STL, glTF/GLB) or a built-in scene: default, plane, wedge, sphere-on-plane, box-room, displaced";

/// Help text of --normal (GBufferOptions::normal).
inline constexpr const char* kNormalHelp =
    "Normal every method integrates about: shading (interpolated vertex normals, the smooth surface a mesh stands for) or geometric "
    "(the triangle's own); it is the G-buffer's N";

/// Declares --normal (kNormalHelp, then `more`) on `cmd`, the same way in every command that has it.
void add_normal_option(CLI::App& cmd, std::string& normal, const std::string& more);
void add_normal_option(CLI::App& cmd, std::optional<std::string>& normal, const std::string& more);

/// The camera options as typed; `request` gets them through camera_request().
struct CameraOptions {
  CameraRequest request;                        ///< width, height, fov and file bound directly.
  std::optional<std::string> eye, target, up;   ///< "x,y,z".
};
/// Declares --width, --height (of the image, or of the `size_of` named), --fov, --eye, --target,
/// --up and --camera on `cmd`, writing into `camera`.
void add_camera_options(CLI::App& cmd, CameraOptions& camera, const std::string& size_of = "Image");
/// The request with --eye, --target and --up parsed (InputError naming the option).
CameraRequest camera_request(const CameraOptions& camera);

/// The falloff options as typed; the request gets them through falloff_request().
struct FalloffOptions {
  std::string membership = "step";
  FalloffRequest request;  ///< radius, radius_fraction and tau bound directly.
};
/// Declares --membership, -R/--radius, --radius-fraction and --tau (unless `with_tau` is false).
void add_falloff_options(CLI::App& cmd, FalloffOptions& falloff, const std::string& membership_help, bool with_tau = true);
FalloffRequest falloff_request(const FalloffOptions& falloff);

/// An option's help from a parameter table: `prefix`, the parameter's one-line help and its valid
/// values ("raytraced: rays per texel ... [an integer in [1, 1048576]]"), so ranges are written once.
std::string param_help(const ParamSchema& schema, std::string_view name, std::string_view prefix = "");

/// "x,y,z" as three finite numbers; InputError naming `option` otherwise.
Vec3 parse_vec3(const std::string& text, const char* option);
/// The non-empty items of `s` between separators `sep` ("a,,b" -> a, b).
std::vector<std::string> split(const std::string& s, char sep);

/// The parameters of a parameter file ({"parameters": {...}}, as ao tune writes, or the object
/// itself) as "key=value" pairs; InputError naming the file when it cannot be read or parsed.
std::vector<std::string> parameter_file_pairs(const std::string& path);

/// Applies "key=value" overrides (and "@file.json" parameter files) to a parameter object. The
/// value is parsed as JSON when it is valid JSON (numbers, true/false, arrays) and taken as a
/// string otherwise. `known` lists the parameters; an unknown key is an InputError naming them.
void apply_param_overrides(nlohmann::json& params, const std::vector<std::string>& overrides, std::string_view method,
                           const nlohmann::json& known);

/// Prints a job's stages' progress unless --quiet: a bar on a terminal, a line every few seconds
/// (log_progress_interval) when stderr is not a terminal (jobs/progress_meter.h), and
/// warnings as "warning: ..." lines and notes unless `json` (the JSON on stdout is then the report).
class StderrReporter {
 public:
  StderrReporter(const GlobalOptions& global, bool json);
  ~StderrReporter();
  const JobReporter& reporter() const { return reporter_; }
  /// Ends the current stage's progress bar.
  void end_stage();

 private:
  struct State;
  std::shared_ptr<State> state_;
  JobReporter reporter_;
};

bool stderr_is_terminal();

}  // namespace ao::cli
