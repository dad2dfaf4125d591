// The one table of AO methods. `ao render --method`, `ao compare`, `ao tune`, `ao view`, the
// Python module and the parametrised tests are driven by it, so a new method is one file pair plus
// one row here. What a method can do (which input it reads, which references it has, whether it
// takes a characteristic function, its extra outputs, whether it keeps state between frames) is a
// typed field of its row, never a parameter name recognised by the caller.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
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
class ConeContext;
struct TransferBuffers;
struct Scene;

/// What methods keep between calls on one scene, for a caller that renders frame after frame (a
/// viewer, a benchmark): cone's mesh closure and voxel grid, transfer's scratch images. A method's
/// output is the same with and without it. The caller owns it and passes it with every call on the
/// same scene; cone starts over when handed another Scene object. Not for concurrent calls.
class MethodCache {
 public:
  MethodCache();
  ~MethodCache();
  MethodCache(MethodCache&&) noexcept;
  MethodCache& operator=(MethodCache&&) noexcept;

  /// Cone's context for `scene`: made on first use, and made again for another Scene object.
  ConeContext& cone(const Scene& scene);
  /// Transfer's scratch images, reused while the image size stays the same.
  TransferBuffers& transfer();

 private:
  std::unique_ptr<ConeContext> cone_;
  std::unique_ptr<TransferBuffers> transfer_;
};

/// Everything a method may read. Screen-space methods read only the G-buffer (and, when asked for
/// an analytic characteristic function, the scene's analytic description); object-space methods
/// (the ray-traced reference, cone) also need the scene, which is absent when the G-buffer came
/// from a file.
struct MethodInput {
  const GBuffer& gbuffer;
  const RayScene* scene = nullptr;  ///< Null when running from a G-buffer file.
  Falloff falloff;                  ///< R and membership; methods that imply their own say so.
  std::uint32_t seed = 0;           ///< Keys every per-pixel sample set.
  ProgressFn progress;
  /// The scene's analytic surfaces (Scene::analytic, world space; the G-buffer's camera takes them
  /// to camera space). Null when running from a G-buffer file; may be set and empty.
  const AnalyticSurfaces* surfaces = nullptr;
  /// Null, or what the methods keep between calls on this scene (MethodCache).
  MethodCache* cache = nullptr;
};

struct MethodOutput {
  /// V in [0,1] per pixel; 1 where the G-buffer is not covered. (Transfer's radiance mode: the
  /// luminance of W, which exceeds 1 where sunlit occluders send more light than the sky.)
  Image<float> visibility;
  Image<Vec3> color;  ///< Optional RGB result (e.g. ambient transfer's W per channel); empty if none.
  /// Further outputs by name, each one of the method's MethodInfo::extras (e.g. "obscurance").
  std::map<std::string, Image<float>> extras;
  /// The ray-traced ground truth: the standard error of V per pixel (0 where not covered); empty
  /// for the other methods. Not written by `ao render`; the Python module returns it.
  Image<float> std_error;
  nlohmann::json stats;  ///< Method-specific numbers for --json (rays, standard errors, ...).
};

/// The characteristic function I(p) of containment, volumetric and transfer, their parameter
/// kCharacteristicParam (VAO fig. 2 and 12; methods/characteristic.h). It is not a field of their
/// Params structs: the kernels take the function itself, and only the registry has the scene's
/// description at hand to build one.
enum class CharacteristicKind {
  Depth,                  ///< "depth": the G-buffer's depth buffer (fig. 2c), with AT 4.3's silhouette elimination as asked.
  Implicit,               ///< "implicit": the scene's half-spaces and sphere exteriors (fig. 2a); no silhouette elimination.
  HeightField,            ///< "height-field": the scene's displacement map over its macro plane (fig. 2b), alone.
  DepthTimesHeightField,  ///< "depth*height-field": their product (fig. 12); elimination applies to the depth factor only.
};
inline constexpr const char* kCharacteristicParam = "characteristic";
/// The accepted values of kCharacteristicParam, in the enum's order.
std::span<const std::string_view> characteristic_names();

/// raytraced's parameter that chooses which reference it renders: one of reference_kind_names()
/// (reference.h), default "obscurance".
inline constexpr const char* kReferenceParam = "reference";

/// Memory a method needs beyond its images, for the check before a run (core/memory.h).
struct MethodMemory {
  std::uint64_t bytes = 0;
  std::string what;  ///< For the message: "a 512^2 x 256 voxel grid".
};

/// One row of the registry. Function members take a complete parameter object (canonical_params).
struct MethodInfo {
  std::string_view name;
  std::string_view summary;  ///< One line for --help.
  /// The ray-traced ground truth itself: `ao compare` judges the other methods against its kinds
  /// and does not list it by default; the viewer accumulates it progressively.
  bool ground_truth = false;
  /// Reads the scene itself (rays, voxels), not only the G-buffer: needs a scene, not a G-buffer file.
  bool needs_scene = false;
  /// Takes kCharacteristicParam (containment, volumetric, transfer).
  bool takes_characteristic = false;
  /// Keeps state between calls on one scene in a MethodCache (cone: its voxel grid; transfer: its
  /// scratch images).
  bool cached = false;
  /// The names MethodOutput::extras may carry, written by `ao render --extras` as
  /// <output-stem>-<name><ext>.
  std::span<const std::string_view> extras;
  /// The parameters that choose which quantity is estimated, and so which reference judges it
  /// (raytraced's reference, transfer's albedo_scale, GTAO's multi_bounce). Every other parameter is
  /// a knob of the estimator, which the reference never follows: a reference depends on the scene,
  /// the camera, R, the membership and its own ray settings only (tests/registry).
  std::span<const std::string_view> quantity_params;
  /// The parameter `--samples` sets; empty when the method has no sample count.
  std::string_view samples_param;
  /// The parameter `--target-error` sets; empty when the method does not stop adaptively.
  std::string_view target_error_param;
  /// The parameter table (defaults, ranges, help); includes kCharacteristicParam / kReferenceParam
  /// where the method has them.
  const ParamSchema& (*params)();
  /// Runs the method; `params` are read through the table (an InputError for a bad one), so any
  /// object canonical_params accepts will do.
  MethodOutput (*run)(const MethodInput& input, const nlohmann::json& params);
  /// The reference that computes exactly the quantity this method estimates (same integral, normal
  /// and R; derived in docs/methods/<name>.md), from the falloff the user asked for and the
  /// method's parameters: what `ao compare` judges it against by default.
  ReferenceSpec (*reference)(const Falloff& requested, const nlohmann::json& params);
  /// The obscurance (VAO eq. 2) membership and R the method approximates or implies (volumetric
  /// AO: cubic; cone tracing: step with R = R_max): `ao compare --reference obscurance`.
  Falloff (*obscurance_falloff)(const Falloff& requested, const nlohmann::json& params);
  /// Whether these parameters read the G-buffer's direct-light pass (transfer's radiance mode).
  bool (*reads_direct_light)(const nlohmann::json& params) = nullptr;
  /// `params` with every value a preset leaves unset (null) filled in as the method uses it (cone's
  /// counts, Alchemy's intensity), for a caller that starts from the values in effect (ao tune);
  /// null for a method without presets.
  nlohmann::json (*resolve_presets)(const nlohmann::json& params) = nullptr;
  /// Memory beyond the images (cone's voxel grid); null when none.
  MethodMemory (*memory)(const nlohmann::json& params) = nullptr;

  /// Every parameter at its default.
  nlohmann::json default_params() const { return params().defaults(); }
  /// `overrides` read over the defaults through the table, checked (InputError naming the
  /// parameter) and written back complete: what the other members take and --json echoes.
  nlohmann::json canonical_params(const nlohmann::json& overrides) const { return params().canonical(overrides); }
  /// Whether `extra` is one of `extras`.
  bool has_extra(std::string_view extra) const;
};

/// The names `ao compare --reference` accepts, besides the kinds of reference.h: "matched" (the
/// method's own, MethodInfo::reference; the default) and "obscurance" (MethodInfo::obscurance_falloff).
inline constexpr const char* kMatchedReference = "matched";

/// The reference called `name` for method `m` with canonical parameters `params`: "matched",
/// "obscurance", "tangent-sphere" (R of the method's obscurance falloff) or "transfer" (its
/// membership and R; the method's albedo_scale when it has one). InputError naming the valid
/// names otherwise.
ReferenceSpec choose_reference(const MethodInfo& m, std::string_view name, const Falloff& requested, const nlohmann::json& params);

/// A parameter table by name: each method's (its name) and the bakers' ("bake-raytraced",
/// "bake-histogram", "bake-high-to-low"): what `ao params`, the generated docs and the Python
/// module list.
struct ParamTableInfo {
  std::string_view name;
  const ParamSchema& (*schema)();
};
std::span<const ParamTableInfo> all_param_tables();
/// The table called `name`; InputError listing the valid names otherwise.
const ParamSchema& find_param_table(std::string_view name);

/// All methods, in the order --help lists them.
std::span<const MethodInfo> all_methods();
/// The method called `name`; InputError listing the valid names otherwise.
const MethodInfo& find_method(std::string_view name);
/// The ground-truth method (MethodInfo::ground_truth).
const MethodInfo& ground_truth_method();

}  // namespace ao
