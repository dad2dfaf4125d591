// Pieces every subcommand shares: choosing the scene, the camera and R from options, the
// progress bar, and timing.
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/camera.h"
#include "ao/core/gbuffer.h"
#include "ao/core/membership.h"
#include "ao/core/progress.h"
#include "ao/io/output_set.h"
#include "ao/scene/mesh.h"

namespace CLI {
class App;
}

namespace ao::cli {

/// Help text of the positional scene argument, shared by the subcommands that take a scene.
inline constexpr const char* kSceneHelp =
    "Mesh file(s) (OBJ, PLY, OFF, STL, glTF/GLB) or a built-in scene: default, plane, wedge, sphere-on-plane, box-room, displaced";

/// Scene from positional arguments: none -> the built-in "default"; one built-in name (when no file
/// of that name exists) -> that scene; otherwise mesh files, merged into one scene.
Scene load_scene_arguments(const std::vector<std::string>& args);
/// The name load_scene_arguments gives the scene, known before loading (for default output names):
/// the built-in name, or the files' names joined by '+'.
std::string scene_arguments_name(const std::vector<std::string>& args);
/// Declares the mesh files among `args` as inputs of `outputs`, so no output may overwrite them.
void add_scene_inputs(OutputSet& outputs, const std::vector<std::string>& args);

/// Camera options as given on the command line; unset ones come from the scene.
struct CameraOptions {
  std::optional<std::string> eye, target, up;  ///< "x,y,z" in world units.
  std::optional<float> fov;                    ///< Vertical, degrees.
  int width = 1280, height = 720;
  /// A camera JSON (io/camera_json.h): its view, and its size unless --width/--height were given.
  std::optional<std::string> file;
  bool width_set = false, height_set = false;  ///< Whether --width/--height were given explicitly.
};
/// Declares --width, --height (of the image, or of the `size_of` named), --fov, --eye, --target,
/// --up and --camera on `cmd`, writing into `camera`; call note_camera_size_given from the
/// subcommand's callback.
void add_camera_options(CLI::App& cmd, CameraOptions& camera, const std::string& size_of = "Image");
/// Records whether --width/--height were given (a camera file's size applies only when not).
void note_camera_size_given(const CLI::App& cmd, CameraOptions& camera);
/// The camera file if given, else the scene's preferred view if it has one, else auto-framing of its bounds from above and in
/// front; any option given overrides the corresponding field. Validated.
Camera choose_camera(const Scene& scene, const CameraOptions& opt);
Vec3 parse_vec3(const std::string& text, const char* option);
/// The non-empty items of `s` between separators `sep` ("a,,b" -> a, b).
std::vector<std::string> split(const std::string& s, char sep);
/// The checks of choose_camera that need no scene, run before anything is loaded: --width and
/// --height in [1, 32768] (when `size_given`: the size does not come from a file), --fov in
/// (0, 180), and --eye/--target/--up as three finite numbers. InputError naming the option, its
/// value and its valid range.
void check_camera_options(const CameraOptions& opt, bool size_given = true);

/// Falloff options: R in world units, or as a fraction of the diagonal of the objects of interest.
struct FalloffOptions {
  std::string membership = "step";
  std::optional<float> radius;    ///< World units.
  float radius_fraction = 0.1f;   ///< Of interest_diagonal(), when radius is unset.
  float tau = 0.0f;
};
/// `diagonal`: what radius_fraction multiplies (interest_diagonal for a scene).
Falloff choose_falloff(const FalloffOptions& opt, float diagonal);
/// The checks of choose_falloff that need no scene (membership name, --radius, --radius-fraction,
/// --tau), run before anything is loaded.
void check_falloff_options(const FalloffOptions& opt);

/// The diagonal the default R is a fraction of: the bounding box of the objects of interest,
/// which are the meshes that are not flat (a ground quad, a floor, a wall: every vertex within
/// 1e-5 of its diagonal from one plane), or every mesh when all are flat. So a model keeps the
/// same default R when a ground plane or walls are added around it; a room made of one closed
/// mesh, or a terrain that is not exactly flat, counts as an object.
float interest_diagonal(const Scene& scene);

/// Help text and parser of --normal (GBufferOptions::normal).
inline constexpr const char* kNormalHelp =
    "Normal every method integrates about: shading (interpolated vertex normals, the smooth surface a mesh stands for) or geometric "
    "(the triangle's own); it is the G-buffer's N";
SurfaceNormal parse_surface_normal(const std::string& text);

/// A progress bar on stderr, shown only when stderr is a terminal, not --quiet, and the stage has
/// run for over a second. Thread-safe; redraws at most ten times a second.
class ProgressBar {
 public:
  ProgressBar(std::string label, bool enabled);
  ~ProgressBar();
  ProgressFn callback();

 private:
  struct State;
  std::shared_ptr<State> state_;
};
bool stderr_is_terminal();

/// Wall-clock stopwatch in milliseconds.
class Stopwatch {
 public:
  double lap_ms();  ///< Milliseconds since construction or the previous lap.

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

/// Applies "key=value" overrides to a method's parameter object. The value is parsed as JSON when
/// it is valid JSON (numbers, true/false, arrays) and taken as a string otherwise. Unknown keys are
/// an InputError listing the method's parameters.
void apply_param_overrides(nlohmann::json& params, const std::vector<std::string>& overrides, std::string_view method);

nlohmann::json to_json(Vec3 v);
nlohmann::json to_json(const Camera& c);

}  // namespace ao::cli
