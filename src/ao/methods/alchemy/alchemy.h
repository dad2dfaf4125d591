// SPDX-License-Identifier: Apache-2.0
// Alchemy screen-space ambient obscurance, based on McGuire, Osman, Bukowski, Hennessy, "The Alchemy
// Screen-Space Ambient Obscurance Algorithm" (HPG 2011). Implements eq. 10,
//
//   A = max(0, 1 - (2 sigma / s) * sum_i max(0, v_i . n + z_C beta) H(r - |v_i|) / (v_i . v_i + epsilon))^k,
//
// with the samples of sec. 2.3 (uniform on the screen-space projection of the disk of radius r about
// C, parallel to the image plane; P_i read from the position buffer) and the Heaviside cut of eq. 9,
// then the separable cross-bilateral filter of sec. 2 / Figure 6 (bilateral.h).
// Convention: the paper's A is the accessibility (eq. 2: AO = 1 - A), i.e. already our visibility
// V, so V = A; no conversion.
//
// The paper states sigma, beta, epsilon and r in metres (its images use r = 0.5 m, sigma = 1,
// beta = 1e-4, epsilon = 1e-4). Eq. 10 is not scale-invariant (sigma is a length, epsilon an area),
// so a scene in other units would need other constants; `meter` (world units per paper metre)
// converts them, and its default takes the chosen r to be the paper's 0.5 m, so the paper's defaults
// give the paper's look at any scene scale. The paper's sigma = 1 is an aesthetic choice (darker
// than the obscurance it estimates); the default is sigma = 0.4, chosen by measurement against the
// reference, and `preset=paper` restores 1. docs/methods/alchemy.md maps every symbol and lists the
// deviations, and derives what the estimator converges to.
#pragma once

#include <cstdint>
#include <optional>

#include <nlohmann/json_fwd.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/membership.h"
#include "ao/core/progress.h"
#include "ao/methods/filters/bilateral.h"
#include "ao/methods/depth_layers.h"
#include "ao/methods/method.h"

namespace ao {

/// Named parameter sets (JSON "preset": "fitted" or "paper").
enum class AlchemyPreset {
  Fitted,  ///< sigma = 0.4: chosen by measurement against the reference (docs/methods/alchemy.md).
  Paper,   ///< sigma = 1: the paper's images.
};

struct AlchemyParams {
  float radius = 0.0f;      ///< r of eq. 9-10, world units, >= 0; 0 = the falloff radius R the caller gives.
  int samples = 12;         ///< s of eq. 10, samples per pixel, [1, 1024]. Default 12, as the paper's Figure 1 and 6.
  /// Which defaults the unset (null) fields take: Fitted (default) or Paper (the paper's own).
  AlchemyPreset preset = AlchemyPreset::Fitted;
  /// sigma of eq. 10, paper metres (scaled by `meter`), >= 0; null = the preset's: Fitted 0.4 (least
  /// RMSE against the reference on the default scene, dragon and cow, docs/methods/alchemy.md),
  /// Paper 1 (the paper's aesthetic default).
  std::optional<float> intensity;
  float contrast = 1.0f;    ///< k of eq. 10, > 0. Paper default 1.
  float bias = 1e-4f;       ///< beta of eq. 10, multiplies z_C (so dimensionless), >= 0. Paper: 1e-4.
  float epsilon = 1e-4f;    ///< epsilon of eq. 10, paper square metres (scaled by meter^2), > 0. Paper: 1e-4.
  float meter = 0.0f;       ///< World units per paper metre, >= 0; 0 = r / 0.5 (r is the paper's 0.5 m). 1 for metric scenes.
  bool filter = true;       ///< Apply the cross-bilateral filter (sec. 2, pass 5). Default on, as the paper.
  BilateralParams bilateral;  ///< The filter's parameters (JSON keys filter_taps, filter_spatial_sigma, filter_plane_sigma).
  DepthLayers layers;         ///< A second depth layer (deep G-buffer): each tap also reads its point (depth_layers.h).

  /// Throws InputError naming the bad field.
  void validate() const;
  /// sigma as used: `intensity`, or the preset's value when it is null.
  float effective_intensity() const { return intensity ? *intensity : preset == AlchemyPreset::Paper ? 1.0f : 0.4f; }
};
/// The parameter table (core/params.h): JSON keys, ranges, defaults, help.
const ParamTable<AlchemyParams>& alchemy_param_table();
void to_json(nlohmann::json& j, const AlchemyParams& p);
/// Rejects unknown keys, wrong types and values out of range with InputError.
void from_json(const nlohmann::json& j, AlchemyParams& p);

/// The constants of eq. 10 in world units, derived from the user's parameters by one pure function.
struct AlchemyConstants {
  float radius;      ///< r, world units.
  float meter;       ///< World units per paper metre.
  float sigma;       ///< sigma * meter, world units.
  float epsilon;     ///< epsilon * meter^2, world units^2.
  float beta;        ///< beta (dimensionless).
};
/// `default_radius` is used when params.radius is 0. Validates.
AlchemyConstants alchemy_constants(const AlchemyParams& params, float default_radius);


struct AlchemyImage {
  Image<float> visibility;  ///< V in [0,1]; 1 where the G-buffer is not covered. Filtered when params.filter.
  Image<float> unfiltered;  ///< V before the filter; empty when params.filter is false.
  double estimator_ms = 0;  ///< Wall time of eq. 10 over the image.
  double filter_ms = 0;     ///< Wall time of the bilateral filter.
};

/// Alchemy AO for every covered pixel of `gbuffer`. Pixel (x, y) draws its sample pattern from
/// pixel_seed(seed, x, y), so the result does not depend on the thread count.
/// With params.layers asking for two, the G-buffer's second layer (GBuffer::second_depth, at the
/// separation in effect; InputError otherwise) adds a point to every tap (depth_layers.h).
AlchemyImage render_alchemy(const GBuffer& gbuffer, const AlchemyParams& params, float default_radius, std::uint32_t seed,
                            const ProgressFn& progress = {});
/// The same with the second layer given (`second_layer`: the G-buffer's size, rendered at the
/// separation params.layers gives with r; read only when they ask for two layers, then not null).
AlchemyImage render_alchemy(const GBuffer& gbuffer, const Image<float>* second_layer, const AlchemyParams& params, float default_radius,
                            std::uint32_t seed, const ProgressFn& progress = {});

/// The method as the registry runs it (method.h): render_alchemy with R = in.falloff.radius as the
/// default radius; with layers = 2 the G-buffer's second layer, or one traced for this run.
MethodOutput run(const MethodInput& in, const AlchemyParams& params);
/// InputError when `params` ask for what the GPU path lacks (two layers).
void check_gpu(const AlchemyParams& params);

}  // namespace ao
