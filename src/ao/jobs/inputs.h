// SPDX-License-Identifier: Apache-2.0
// What every job starts from: the scene (mesh files, a built-in scene, or one made in memory),
// the camera (look-at and field of view, or the scene's own view, or auto-framing) and the falloff
// (R in world units or as a fraction of the objects' size). The requests hold what the caller
// asked for; the functions here turn them into a Scene, a Camera and a Falloff, checking each value
// before anything is loaded.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ao/core/camera.h"
#include "ao/core/gbuffer.h"
#include "ao/core/math.h"
#include "ao/core/membership.h"
#include "ao/io/mesh_io.h"
#include "ao/io/output_set.h"
#include "ao/scene/mesh.h"

namespace ao {

class RayScene;
struct BvhOptions;

/// The scene of a job: mesh files merged into one scene, one built-in scene by name, or a Scene the
/// caller made (which then wins).
struct SceneSource {
  /// Mesh files (OBJ, PLY, OFF, STL, glTF/GLB), or a single built-in name (default, plane, wedge,
  /// sphere-on-plane, box-room, displaced) that is not a file. Empty: the built-in "default".
  std::vector<std::string> args;
  std::shared_ptr<const Scene> scene;  ///< Made by the caller; validated (validate_and_prepare).

  /// The scene's name, known before loading: the built-in name, the files' names joined by '+', or
  /// the caller's scene's name.
  std::string name() const;
  /// The mesh files it names: none for the caller's scene or a built-in one.
  std::vector<std::string> files() const;
  /// Declares the mesh files as inputs of `outputs`, so that no output may overwrite them.
  void declare_inputs(OutputSet& outputs) const;
  /// The scene: the caller's, or the files loaded and merged (InputError naming a bad file). Its
  /// load warnings are in Scene::warnings.
  std::shared_ptr<const Scene> load(const LoadOptions& options = {}) const;
};

/// The diagonal the default R is a fraction of: the bounding box of the objects of interest,
/// which are the meshes that are not flat (a ground quad, a floor, a wall: every vertex within
/// 1e-5 of its diagonal from one plane), or every mesh when all are flat. So a model keeps the
/// same default R when a ground plane or walls are added around it; a room made of one closed
/// mesh, or a terrain that is not exactly flat, counts as an object.
float interest_diagonal(const Scene& scene);

/// A scene ready to render from many cameras: the scene, its BVH and the diagonal of its objects.
struct PreparedScene {
  std::shared_ptr<const Scene> scene;
  std::unique_ptr<RayScene> rays;
  float radius_basis = 1.0f;  ///< interest_diagonal(*scene).

  /// Builds the BVH after checking its memory (SystemError naming `what` and the estimate when the
  /// machine has too little).
  PreparedScene(std::shared_ptr<const Scene> scene, const std::string& what, const BvhOptions& options);
  explicit PreparedScene(std::shared_ptr<const Scene> scene);
  PreparedScene(PreparedScene&&) noexcept;
  PreparedScene& operator=(PreparedScene&&) noexcept;
  ~PreparedScene();
};

/// The camera of a job. Every field that is set overrides the view the camera starts from: the
/// camera file's if given, else the scene's own view if it has one, else auto-framing of the
/// scene's bounds from the front right and above.
struct CameraRequest {
  std::optional<Vec3> eye, target, up;  ///< World units; up: a direction.
  std::optional<float> fov;             ///< Vertical field of view, degrees, (0, 180).
  std::optional<int> width, height;     ///< Pixels, [1, kMaxImageSide]; unset: the camera file's, else the default.
  std::optional<std::filesystem::path> file;  ///< A camera JSON (io/camera_json.h), as ao view's S key writes.
  int default_width = 1280, default_height = 720;  ///< The job's own size when neither the caller nor a file gives one.

  /// A request with nothing set and the job's own default size.
  static CameraRequest sized(int width, int height) {
    CameraRequest r;
    r.default_width = width, r.default_height = height;
    return r;
  }

  /// InputError naming the option (--width, --fov, ...), its value and its valid range: the checks
  /// that need no scene, made before anything is loaded.
  void validate() const;
};

/// The camera `request` asks for in `scene`; validated.
Camera choose_camera(const Scene& scene, const CameraRequest& request);

/// The falloff of a job: R in world units, or a fraction of interest_diagonal.
struct FalloffRequest {
  Membership membership = Membership::Step;
  std::optional<float> radius;   ///< World units, > 0 and finite; unset: radius_fraction x the diagonal.
  float radius_fraction = 0.1f;  ///< (0, 10].
  float tau = 0.0f;              ///< exp membership: 1 / world units, >= 0; 0 selects 3/R.

  /// InputError naming the option for a value out of its range, before anything is loaded.
  void validate() const;
};

/// `request` with R resolved against `diagonal` (what radius_fraction multiplies); validated.
Falloff choose_falloff(const FalloffRequest& request, float diagonal);

/// The membership called `name`; InputError "--membership: unknown 'x' (known: ...)".
Membership membership_from_name(const std::string& name);
/// The normal called `name` ("shading" or "geometric"); InputError naming --normal otherwise.
SurfaceNormal surface_normal_from_name(const std::string& name);
/// "shading" or "geometric".
const char* to_string(SurfaceNormal normal);

}  // namespace ao
