// SPDX-License-Identifier: Apache-2.0
// What the runs of the screen-space methods share: screen_space_method_internal.h.
#include "ao/methods/screen_space_method_internal.h"

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/scene/procedural.h"

namespace ao::detail {

namespace {

std::string joined_names(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

}  // namespace

std::shared_ptr<const Image<float>> second_layer_for(const MethodInput& in, float separation, std::string_view method) {
  const GBuffer& g = in.gbuffer;
  if (has_second_layer(g, separation)) return {std::shared_ptr<void>(), &g.second_depth};  // not owned: g outlives the run
  if (!in.trace_second_layer)
    throw InputError(std::string(method) + ": layers=2 traces the second depth layer in the scene, and this G-buffer came without " +
                     "a scene (a G-buffer file or arrays hold one layer): give the scene, or use layers=1");
  return std::make_shared<const Image<float>>(in.trace_second_layer(separation));
}

void check_analytic_characteristic(const MethodInput& in, CharacteristicKind kind, const DepthLayers& layers, std::string_view method) {
  const std::string name(to_string(kind));
  if (layers.layers == 2)
    throw InputError(std::string(method) + ": layers=2 is a second layer of the depth buffer, and characteristic " + name +
                     " is analytic: use layers=1 with it");
  if (layers.thickness > 0)
    throw InputError(std::string(method) + ": thickness takes the depth buffer's surfaces for sheets, and characteristic " + name +
                     " is analytic, with a solid of its own: use thickness=0 with it");
  const bool implicit = kind == CharacteristicKind::Implicit;
  const std::string builtins = joined_names(implicit ? builtin_scenes_with_implicit_surface() : builtin_scenes_with_height_field());
  const std::string what = implicit ? "implicit surface" : "height field";
  if (!in.surfaces)
    throw InputError(std::string(method) + ": characteristic " + name + " reads the scene's " + what +
                     ", and a G-buffer file has none: give a built-in scene that has one (" + builtins + ") instead of --gbuffer-in");
  if (implicit ? !in.surfaces->implicit : !in.surfaces->height_field)
    throw InputError(std::string(method) + ": characteristic " + name + " needs a scene with an analytic " + what + ", and " +
                     (in.scene ? "'" + in.scene->name + "'" : std::string("this scene")) + " has none (built-in scenes with one: " + builtins +
                     ")");
}

void check_gpu_screen_space(std::string_view method, CharacteristicKind kind, const DepthLayers& layers) {
  if (kind != CharacteristicKind::Depth)
    throw InputError(std::string(method) + " on the GPU reads the depth buffer only: characteristic " + std::string(to_string(kind)) +
                     " runs on the CPU (--device cpu)");
  if (layers.layers != 1)
    throw InputError(std::string(method) + ": layers=2 (a second depth layer) runs on the CPU backend only; the GPU shaders read one layer");
}

void add_characteristic_stats(MethodOutput& out, CharacteristicKind kind, bool elimination) {
  if (kind == CharacteristicKind::Depth) return;
  out.stats["characteristic"] = to_string(kind);
  out.stats["silhouette_elimination"] = kind == CharacteristicKind::DepthTimesHeight && elimination ? "depth-buffer factor only" : "off";
}

}  // namespace ao::detail
