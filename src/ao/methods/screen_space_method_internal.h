// SPDX-License-Identifier: Apache-2.0
// What the runs of containment, volumetric and transfer share (their `run` overloads, method.h),
// not installed: the characteristic function their parameters ask for, built in the G-buffer's
// camera space from the depth buffer (with a second layer when asked) or from the scene's analytic
// surfaces, and the second depth layer of Alchemy and the screen-space methods.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "ao/core/error.h"
#include "ao/methods/characteristic.h"
#include "ao/methods/depth_layers.h"
#include "ao/methods/method.h"

namespace ao::detail {

/// The second depth layer a method run with `layers` = 2 reads: the G-buffer's own when it has one
/// at `separation`, else traced in the scene for this run (MethodInput::trace_second_layer);
/// InputError naming `method` when there is neither.
std::shared_ptr<const Image<float>> second_layer_for(const MethodInput& in, float separation, std::string_view method);

/// InputError for a characteristic function the scene (or a G-buffer file) cannot give: an analytic
/// kind with layers = 2, or a scene without the analytic surface `kind` reads.
void check_analytic_characteristic(const MethodInput& in, CharacteristicKind kind, const DepthLayers& layers, std::string_view method);

/// InputError when a screen-space method's parameters ask for what its GPU path lacks: the GPU
/// reads the depth buffer only (no analytic characteristic) and one layer of it (with its sheets of
/// a thickness, as the CPU).
void check_gpu_screen_space(std::string_view method, CharacteristicKind kind, const DepthLayers& layers);

/// What --json reports about the characteristic function a method ran with (nothing for the default).
void add_characteristic_stats(MethodOutput& out, CharacteristicKind kind, bool elimination);

/// Builds the characteristic function of `kind` in the G-buffer's camera space and calls
/// fn(ch, kernel_elimination): whether the kernel's own silhouette elimination (AT 4.3) is to run.
/// `elimination` is the user's silhouette_elimination; `limit` the distance in front of a sample
/// point beyond which the depth-buffer factor of the product counts as a distant foreground object.
template <class Fn>
void with_characteristic(const MethodInput& in, CharacteristicKind kind, const DepthLayers& layers, std::string_view method, bool elimination,
                         float limit, Fn&& fn) {
  const GBuffer& g = in.gbuffer;
  check_thickness(layers, std::string(method));
  if (kind == CharacteristicKind::Depth && !reads_second_layer(layers)) return fn(DepthBufferCharacteristic(g), elimination);
  if (kind == CharacteristicKind::Depth) {
    const float separation = layer_separation(layers, in.falloff.radius);
    return fn(DepthBufferCharacteristic(g, layers.layers == 2 ? second_layer_for(in, separation, method) : nothing_behind(g), separation),
              elimination);
  }
  check_analytic_characteristic(in, kind, layers, method);
  // Analytic factors: their inner regions are solid, so the kernels' elimination stays off for them.
  switch (kind) {
    case CharacteristicKind::Implicit: return fn(implicit_characteristic(*in.surfaces->implicit, g.camera), false);
    case CharacteristicKind::HeightField: return fn(height_field_characteristic(*in.surfaces->height_field, g.camera), false);
    default: {
      const EliminatedDepthTimesHeightField product{{DepthBufferCharacteristic(g), elimination ? limit : kInfinity},
                                                    height_field_characteristic(*in.surfaces->height_field, g.camera)};
      return fn(product, false);
    }
  }
}

}  // namespace ao::detail
