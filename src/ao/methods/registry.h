// The one table of AO methods. `ao render --method`, `ao compare` and the parametrised tests are
// driven by it, so a new method is one file pair plus one row here.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/membership.h"
#include "ao/core/params.h"
#include "ao/core/progress.h"
#include "ao/reference/reference.h"
#include "ao/scene/analytic.h"

namespace ao {

class RayScene;

/// What methods keep between calls on one scene, for a caller that renders frame after frame (a
/// viewer, a benchmark): cone's mesh closure and voxel grid (ConeContext), transfer's scratch
/// images. A method's output is the same with and without it. The caller owns it, passes it with
/// every call on the same scene and makes a new one for another scene (cone also starts over when
/// handed another Scene object). Each method keeps one entry, of one type, under its name. Not for
/// concurrent calls.
class MethodCache {
 public:
  /// The entry of `method`, constructed from `args` on first use.
  template <class T, class... Args>
  T& entry(std::string_view method, Args&&... args) {
    auto it = entries_.find(method);
    if (it == entries_.end()) it = entries_.emplace(std::string(method), std::make_shared<T>(std::forward<Args>(args)...)).first;
    return *static_cast<T*>(it->second.get());
  }
  /// A new entry of `method` constructed from `args`, in place of the old one.
  template <class T, class... Args>
  T& replace(std::string_view method, Args&&... args) {
    std::shared_ptr<void>& slot = entries_[std::string(method)];
    slot = std::make_shared<T>(std::forward<Args>(args)...);
    return *static_cast<T*>(slot.get());
  }

 private:
  std::map<std::string, std::shared_ptr<void>, std::less<>> entries_;
};

/// Everything a method may read. Screen-space methods read only the G-buffer (and, when asked for
/// an analytic characteristic function, the scene's analytic description); object-space methods
/// (the ray-traced reference) also need the scene, which is absent when the G-buffer came from a file.
struct MethodInput {
  const GBuffer& gbuffer;
  const RayScene* scene = nullptr;  ///< Null when running from --gbuffer-in.
  Falloff falloff;                  ///< R and membership; methods that imply their own say so.
  std::uint32_t seed = 0;           ///< Keys every per-pixel sample set.
  ProgressFn progress;
  /// The scene's analytic surfaces (Scene::analytic, world space; the G-buffer's camera takes them
  /// to camera space). Null when running from --gbuffer-in; may be set and empty.
  const AnalyticSurfaces* surfaces = nullptr;
  /// Null, or what the methods keep between calls on this scene (MethodCache).
  MethodCache* cache = nullptr;
};

/// The registry-level parameter of containment, volumetric and transfer that chooses their
/// characteristic function I(p) (VAO fig. 2 and 12; methods/characteristic.h). It is not a field of
/// their Params structs: the library calls take the function itself (containment_ao(g, ch, ...)),
/// and only the registry has the scene's description at hand to build one. Values:
///  - "depth" (default): the G-buffer's depth buffer (VAO fig. 2c), with AT 4.3's silhouette
///    elimination as `silhouette_elimination` says;
///  - "implicit": the scene's half-spaces and sphere exteriors (fig. 2a; built-ins plane, wedge,
///    sphere-on-plane). Silhouette elimination is not applied: the inner region of an analytic
///    surface is solid, so a point in it is occluded however far in front the surface is;
///  - "height-field": the scene's displacement map over its macro plane (fig. 2b; built-in
///    displaced), alone: other objects do not occlude. No silhouette elimination, as implicit;
///  - "depth*height-field": their product (fig. 12): occluded when either says so. Silhouette
///    elimination, when on, applies to the depth-buffer factor only (SilhouetteEliminated).
inline constexpr const char* kCharacteristicParam = "characteristic";
/// The accepted values of kCharacteristicParam, in the order above.
std::span<const std::string_view> characteristic_names();

struct MethodOutput {
  /// V in [0,1] per pixel; 1 where the G-buffer is not covered. (Transfer's radiance mode: the
  /// luminance of W, which exceeds 1 where sunlit occluders send more light than the sky.)
  Image<float> visibility;
  Image<Vec3> color;        ///< Optional RGB result (e.g. ambient transfer's W per channel); empty if none.
  std::map<std::string, Image<float>> extras;  ///< Optional further outputs by name (e.g. "obscurance").
  nlohmann::json stats;     ///< Method-specific numbers for --json (rays, standard errors, ...).
};

struct MethodInfo {
  std::string_view name;
  std::string_view summary;       ///< One line for --help.
  bool needs_scene;               ///< True for object-space methods.
  /// Parameters with their defaults, as JSON (the method's Params struct, serialised).
  nlohmann::json (*default_params)();
  /// Validates `params` (unknown keys and bad values throw InputError) and runs the method.
  MethodOutput (*run)(const MethodInput& input, const nlohmann::json& params);
  /// The reference that computes exactly the quantity this method estimates (same integral, normal
  /// and R; derived in docs/methods/<name>.md), from the falloff the user asked for and the method's
  /// parameters: what `ao compare` judges it against by default (e.g. volumetric AO: the tangent
  /// sphere's visible fraction; ambient transfer: W with the occluders' albedo).
  ReferenceSpec (*reference)(const Falloff& requested, const nlohmann::json& params);
  /// The obscurance (VAO eq. 2) membership and R the method approximates or implies (volumetric AO:
  /// cubic; cone tracing: step with R = R_max): `ao compare --reference obscurance`.
  Falloff (*obscurance_falloff)(const Falloff& requested, const nlohmann::json& params);
  /// The parameters as described by the method's parameter table (core/params.h), in table order,
  /// plus the registry's own (kCharacteristicParam); null for a method without a table.
  std::vector<ParamSpec> (*param_specs)() = nullptr;
  /// Reads `params` through the method's table (InputError, one line, for an unknown key, a wrong
  /// type or a value out of range) and writes every parameter back: what --json echoes. Null for
  /// a method without a table.
  nlohmann::json (*canonical_params)(const nlohmann::json& params) = nullptr;
};

/// The registry-level parameter of `raytraced` that chooses which reference it renders: one of
/// reference_kind_names() (reference.h), default "obscurance". Like kCharacteristicParam it is not
/// a field of RaytracedParams: the registry dispatches on it (render_reference).
inline constexpr const char* kReferenceParam = "reference";

/// The names `ao compare --reference` accepts, besides the kinds of reference.h: "matched" (the
/// method's own, MethodInfo::reference; the default) and "obscurance" (MethodInfo::obscurance_falloff).
inline constexpr const char* kMatchedReference = "matched";

/// The reference called `name` for method `m` with parameters `params` (a complete parameter
/// object, as default_params() gives): "matched", "obscurance", "tangent-sphere" (R of the method's
/// obscurance falloff) or "transfer" (its membership and R; the method's albedo_scale when it has
/// one). InputError naming the valid names otherwise.
ReferenceSpec choose_reference(const MethodInfo& m, std::string_view name, const Falloff& requested, const nlohmann::json& params);

/// All methods, in the order --help lists them.
std::span<const MethodInfo> all_methods();
/// The method called `name`; InputError listing the valid names otherwise.
const MethodInfo& find_method(std::string_view name);

}  // namespace ao
