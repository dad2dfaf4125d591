// SPDX-License-Identifier: Apache-2.0
// Containment-test ambient occlusion. Based on Szirmay-Kalos, Umenhoffer, Toth, Szecsi, Sbert,
// "Volumetric Ambient Occlusion for Real-Time Rendering and Games" (VAO), eq. 4-5, with the
// samples of Umenhoffer, Toth, Szirmay-Kalos, "Efficient Methods for Ambient Lighting" (AT),
// sec. 4-4.3:
//
//   O(x) ~ (1/n) sum_i I(x + X_i T + Y_i B + Z_i N)                              (VAO eq. 5)
//
// with (X_i, Y_i, Z_i) = w_i r_i, w_i cosine distributed and r_i = mu^-1(xi_i) (AT eq. 8), so the
// estimate approximates the obscurance of eq. 2 with the user's membership mu, exactly when a
// ray meets the surface at most once within R. The paper's O is already openness: V = O.
// Additions from the papers: Poisson-disk samples by Lloyd relaxation (AT 4.1), 4x4 interleaved
// sampling + depth-aware box filter (VAO and AT 4.2), silhouette-shadow elimination (AT 4.3).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/membership.h"
#include "ao/methods/characteristic.h"
#include "ao/methods/depth_layers.h"
#include "ao/methods/filters/interleave.h"
#include "ao/methods/method.h"

namespace ao {

struct ContainmentParams {
  int samples = 12;                   ///< n in eq. 5: test points per pixel, [1, 256].
  /// m: containment tests along each ray at r_i j/m, j = 1..m (AT sec. 4), [1, 8]; 1 = eq. 5's end
  /// point only. Default 3: the least error per ms on the default scene and the dragon (docs/methods/containment.md).
  int ray_steps = 3;
  bool silhouette_elimination = true; ///< AT 4.3: a point is occluded only if the surface in front of it is less than R in front.
  float bias = 0.0f;                  ///< Depth-test bias, world units, >= 0; 0 = auto (one pixel footprint x (1 + tan theta_v)).
  InterleaveOptions interleave;       ///< sec. 4.2 options.
  DepthLayers layers;                 ///< A second depth layer (deep G-buffer), read from GBuffer::second_depth (depth_layers.h).
  /// The characteristic function I(p) run() builds (characteristic.h); containment_ao takes the
  /// function itself and does not read this.
  CharacteristicKind characteristic = CharacteristicKind::Depth;

  /// Throws InputError naming the bad field.
  void validate() const;
};
/// The parameter table (core/params.h): JSON keys, ranges, defaults, help.
const ParamTable<ContainmentParams>& containment_param_table();
void to_json(nlohmann::json& j, const ContainmentParams& p);
/// Rejects unknown keys, wrong types and values out of range with InputError.
void from_json(const nlohmann::json& j, ContainmentParams& p);

/// V per pixel (1 where not covered) with characteristic function `ch` (characteristic.h;
/// instantiated for DepthBufferCharacteristic, ImplicitCharacteristic, HeightFieldCharacteristic,
/// DepthTimesHeightField and EliminatedDepthTimesHeightField), interleaved and filtered as `params`
/// say. Deterministic for a seed, independent of the thread count. With an analytic `ch`, turn
/// silhouette_elimination off: their inner regions are solid (the registry does, registry.h).
template <class Characteristic>
Image<float> containment_ao(const GBuffer& g, const Characteristic& ch, const Falloff& falloff, const ContainmentParams& params,
                            std::uint32_t seed);

/// The screen-space method: containment_ao with the G-buffer's depth buffer.
Image<float> containment_ao(const GBuffer& g, const Falloff& falloff, const ContainmentParams& params, std::uint32_t seed);

/// The method as the registry runs it (method.h): containment_ao with the characteristic function
/// `params` ask for, built from the G-buffer, its second layer or the scene's analytic surfaces.
MethodOutput run(const MethodInput& in, const ContainmentParams& params);
/// InputError when `params` ask for what the GPU path lacks (an analytic characteristic, two layers).
void check_gpu(const ContainmentParams& params);

}  // namespace ao
