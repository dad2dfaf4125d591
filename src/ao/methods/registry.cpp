#include "ao/methods/registry.h"

#include <array>

#include "ao/core/error.h"
#include "ao/reference/raytraced.h"

namespace ao {

namespace {

MethodOutput run_raytraced(const MethodInput& in, const nlohmann::json& j) {
  if (!in.scene)
    throw InputError("method raytraced traces rays in the scene, and a G-buffer file has none: give a scene instead of --gbuffer-in");
  RaytracedParams p = j.get<RaytracedParams>();
  p.validate();
  RaytracedImage img = render_raytraced(*in.scene, in.gbuffer, in.falloff, p, in.seed, in.progress);
  MethodOutput out;
  out.visibility = std::move(img.visibility);
  out.stats = {{"rays", img.rays}, {"mean_std_error", img.mean_std_error}, {"max_std_error", img.max_std_error}};
  return out;
}

const std::array kMethods{
    MethodInfo{"raytraced", "ground truth: Monte Carlo obscurance with Embree rays, any membership", true,
               [] { return nlohmann::json(RaytracedParams{}); }, run_raytraced,
               [](const Falloff& requested, const nlohmann::json&) { return requested; }},
};

}  // namespace

std::span<const MethodInfo> all_methods() { return kMethods; }

const MethodInfo& find_method(std::string_view name) {
  std::string names;
  for (const MethodInfo& m : kMethods) {
    if (m.name == name) return m;
    names += (names.empty() ? "" : ", ") + std::string(m.name);
  }
  throw InputError("unknown method '" + std::string(name) + "' (known: " + names + ")");
}

}  // namespace ao
