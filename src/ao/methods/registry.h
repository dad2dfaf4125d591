// The one table of AO methods. `ao render --method`, `ao compare` and the parametrised tests are
// driven by it, so a new method is one file pair plus one row here.
#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/membership.h"
#include "ao/core/progress.h"

namespace ao {

class RayScene;

/// Everything a method may read. Screen-space methods read only the G-buffer; object-space
/// methods (the ray-traced reference) also need the scene, which is absent when the G-buffer came
/// from a file.
struct MethodInput {
  const GBuffer& gbuffer;
  const RayScene* scene = nullptr;  ///< Null when running from --gbuffer-in.
  Falloff falloff;                  ///< R and membership; methods that imply their own say so.
  std::uint32_t seed = 0;           ///< Keys every per-pixel sample set.
  ProgressFn progress;
};

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
  /// The ground-truth integral this method approximates, as the falloff `ao compare` gives the
  /// ray-traced reference, from the falloff the user asked for and the method's parameters (e.g.
  /// volumetric AO implies the cubic membership; cone tracing is classical AO with R = R_max).
  Falloff (*reference_falloff)(const Falloff& requested, const nlohmann::json& params);
};

/// All methods, in the order --help lists them.
std::span<const MethodInfo> all_methods();
/// The method called `name`; InputError listing the valid names otherwise.
const MethodInfo& find_method(std::string_view name);

}  // namespace ao
