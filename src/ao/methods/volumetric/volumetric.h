// SPDX-License-Identifier: Apache-2.0
// Volumetric ambient occlusion. Based on Szirmay-Kalos, Umenhoffer, Toth, Szecsi, Sbert,
// "Volumetric Ambient Occlusion for Real-Time Rendering and Games" (VAO), eq. 6-7:
//
//   V(x) = |free part of S| / |S| ~ (1/F) sum_i dz_i                                   (eq. 7)
//
// S is the tangent sphere of radius R/2 centred at x + N R/2 (fig. 4). Its volume is summed as n
// pipes along the view axis through Poisson-disk samples (x_i, y_i) of the sphere's great disk
// perpendicular to the view axis (fig. 7); pipe i enters the sphere at z_c - (R/2) h_i and exits at
// z_c + (R/2) h_i, h_i = sqrt(1 - x_i^2 - y_i^2), and its free length is
//   dz_i = clamp(z*_i - z_entry_i, 0, z_exit_i - z_entry_i)                            (fig. 7a-c)
// with z*_i the separating surface's depth along the pipe (characteristic.h). The normaliser is
// the weighted-importance F = R sum_i h_i (default, eq. after 7), or the analytic 2Rn/3 = |S| /
// (R^2 pi / (4n)) (option). V is openness already, as the paper defines it.
//
// Which reference: VAO shows (eq. after fig. 5) that the tangent-sphere volume equals the
// obscurance integral when dmu/dr ~ r^2, i.e. mu(r) = (r/R)^3 with the SAME R: the tangent sphere
// has radius R/2, so its points lie at distances up to R (its diameter) from x. So volumetric AO
// approximates the ray-traced obscurance with Membership::Cubic and radius R.
#pragma once

#include <cstdint>

#include <nlohmann/json_fwd.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/membership.h"
#include "ao/methods/characteristic.h"
#include "ao/methods/depth_layers.h"
#include "ao/methods/filters/interleave.h"
#include "ao/methods/method.h"

namespace ao {

enum class VolumeNormalizer {
  WeightedImportance,  ///< F = R sum_i sqrt(1 - x_i^2 - y_i^2): the samples' own estimate of |S| (default).
  Analytic,            ///< F = 2 R n / 3 from the exact |S| = 4 (R/2)^3 pi / 3; V may exceed 1 and is clamped.
};

struct VolumetricParams {
  int samples = 12;                   ///< n in eq. 6-7: pipes per pixel, [1, 256].
  VolumeNormalizer normalizer = VolumeNormalizer::WeightedImportance;  ///< F in eq. 7; JSON "wis" or "analytic".
  bool silhouette_elimination = true; ///< AT sec. 4.3 applied to pipes: a surface more than R in front of a pipe's entry point does not occlude it.
  float bias = 0.0f;                  ///< Added to z* - z_entry, world units, >= 0; 0 = auto (as containment).
  InterleaveOptions interleave;       ///< sec. 4.2 options (rotation of the disk samples about the view axis).
  DepthLayers layers;                 ///< A second depth layer (deep G-buffer), read from GBuffer::second_depth (depth_layers.h).

  /// The characteristic function I(p) run() builds (characteristic.h); the *_ao functions take the
  /// function itself and do not read this.
  CharacteristicKind characteristic = CharacteristicKind::Depth;

  /// Throws InputError naming the bad field.
  void validate() const;
};
/// The parameter table (core/params.h): JSON keys, ranges, defaults, help.
const ParamTable<VolumetricParams>& volumetric_param_table();
void to_json(nlohmann::json& j, const VolumetricParams& p);
/// Rejects unknown keys, wrong types and values out of range with InputError.
void from_json(const nlohmann::json& j, VolumetricParams& p);

/// V per pixel (1 where not covered) for radius R = falloff.radius (the membership is implied:
/// cubic), with characteristic function `ch` (instantiated as containment_ao's). Deterministic.
template <class Characteristic>
Image<float> volumetric_ao(const GBuffer& g, const Characteristic& ch, float radius, const VolumetricParams& params, std::uint32_t seed);

/// The screen-space method: volumetric_ao with the G-buffer's depth buffer.
Image<float> volumetric_ao(const GBuffer& g, float radius, const VolumetricParams& params, std::uint32_t seed);

/// The method as the registry runs it (method.h): volumetric_ao with R = in.falloff.radius (the
/// membership is implied: cubic) and the characteristic function `params` ask for.
MethodOutput run(const MethodInput& in, const VolumetricParams& params);
/// InputError when `params` ask for what the GPU path lacks (an analytic characteristic, two layers).
void check_gpu(const VolumetricParams& params);

}  // namespace ao
