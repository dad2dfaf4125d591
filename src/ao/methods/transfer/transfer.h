// SPDX-License-Identifier: Apache-2.0
// Ambient transfer. Based on Umenhoffer, Toth, Szirmay-Kalos, "Efficient Methods for Ambient
// Lighting" (AT), eq. 6, 7 and 9:
//
//   W(x) ~ sum_i I(p_i) / (n - sum_i (1 - I(p_i)) a~(p_i))        per RGB channel   (eq. 9)
//
// with the containment-test samples p_i = x + X_i T + Y_i B + Z_i N of eq. 8 (cosine directions,
// r_i = mu^-1(xi)), I(p_i) the product of m tests at r_i j/m, j = 1..m, along the ray (sec. 4),
// and a~ the albedo read at the projection of the first test point found occluded (sec. 4). W is
// obscurance plus the light of further bounces off nearby surfaces of albedo a, under the
// assumption W(y) ~ W(x) (eq. 6); W >= O, and W -> O as a -> 0. The obscurance O = (1/n) sum I
// (eq. 5) comes out of the same tests. Shading is L = a W La (eq. 2).
//
// Radiance mode (TransferReflectance::Radiance), AT 4.1's remark after eq. 9 that the radiance
// stored in the pixel may replace the albedo, "to include the effect of the directional and point
// lights in the indirect illumination". Our reading (derivation in docs/methods/transfer.md):
// with direct lights an occluder reflects Lr(y) = a(y) W(y) La + Ld(y), Ld its directly lit
// radiance (GBuffer::direct, in units of La). Put into eq. 4 with W(y) ~ W(x) as for eq. 6:
//
//   W(x) ~ (sum_i I(p_i) + sum_i (1 - I(p_i)) Ld~(p_i)/La) / (n - sum_i (1 - I(p_i)) a~(p_i))
//
// eq. 9 with a numerator term from the direct radiance at the occluded test point's pixel; Ld = 0
// gives eq. 9 exactly. (Radiance in eq. 9's denominator in place of a~ would add a radiance to a
// pure number and divide by zero for occluders of Ld >= 1.) W may exceed 1 there, and shading is
// L = a W La + Ld.
//
// Output: `color` = W per channel, `visibility` = Rec. 709 luminance of W, extra "obscurance" = O.
// The reference is the ray-traced W of eq. 6 (reference/transfer_reference.h), the integral eq. 9
// estimates; the obscurance of the membership, which W approaches as the albedo goes to 0, by name.
#pragma once

#include <array>
#include <cstdint>

#include <nlohmann/json_fwd.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/membership.h"
#include "ao/methods/characteristic.h"
#include "ao/methods/depth_layers.h"
#include "ao/methods/filters/interleave.h"
#include "ao/methods/method.h"

namespace ao {

/// What an occluder sends back towards the shaded point, besides blocking the sky.
enum class TransferReflectance {
  Albedo,    ///< eq. 9: its albedo a~ times the ambient transfer (a~ W La).
  Radiance,  ///< AT 4.1's variant: also its direct radiance Ld~ (a~ W La + Ld~), from GBuffer::direct.
};

struct TransferParams {
  int samples = 12;                   ///< n in eq. 9: rays per pixel, [1, 256].
  int ray_steps = 2;                  ///< m: containment tests per ray (sec. 4: "in practice 1 or 2"), [1, 8].
  bool silhouette_elimination = true; ///< AT 4.3: occluded only if the surface in front is less than R in front.
  float bias = 0.0f;                  ///< Depth-test bias, world units, >= 0; 0 = auto (as containment).
  float albedo_scale = 1.0f;          ///< Multiplies a~ and Ld~ (studies of W -> O as albedo -> 0), [0, 1].
  /// "albedo" (default, eq. 9) or "radiance" (reads GBuffer::direct, which must then be there).
  TransferReflectance reflectance = TransferReflectance::Albedo;
  InterleaveOptions interleave;       ///< sec. 4.2 options; the filter runs on W and O alike.
  DepthLayers layers;                 ///< A second depth layer (deep G-buffer), read from GBuffer::second_depth (depth_layers.h).

  /// The characteristic function I(p) run() builds (characteristic.h); the *_ao functions take the
  /// function itself and do not read this.
  CharacteristicKind characteristic = CharacteristicKind::Depth;

  /// Throws InputError naming the bad field.
  void validate() const;
};
/// The parameter table (core/params.h): JSON keys, ranges, defaults, help.
const ParamTable<TransferParams>& transfer_param_table();
void to_json(nlohmann::json& j, const TransferParams& p);
/// Rejects unknown keys, wrong types and values out of range with InputError.
void from_json(const nlohmann::json& j, TransferParams& p);

struct TransferImage {
  Image<Vec3> transfer;      ///< W per RGB channel, in [0, 1] (radiance mode: >= 0, > 1 near lit occluders); 1 where not covered.
  Image<float> obscurance;   ///< O (eq. 5), in [0, 1]; 1 where not covered.
  Image<float> luminance;    ///< Rec. 709 luminance of W: the method's scalar visibility.
};

/// Ambient transfer with characteristic function `ch` (instantiated as containment_ao's) and the
/// multi-bounce reflectance `indirect` (a~, normally the G-buffer's albedo; same size) read at
/// occluded test points. With params.reflectance == Radiance the occluders' direct radiance is
/// read from g.direct as well (InputError when g.direct is empty or of another size).
/// Deterministic for a seed, independent of threads.
template <class Characteristic>
TransferImage transfer_ao(const GBuffer& g, const Characteristic& ch, const Image<Vec3>& indirect, const Falloff& falloff,
                          const TransferParams& params, std::uint32_t seed);

/// The screen-space method: depth buffer, G-buffer albedo.
TransferImage transfer_ao(const GBuffer& g, const Falloff& falloff, const TransferParams& params, std::uint32_t seed);

/// The method as the registry runs it (method.h): transfer_ao with the G-buffer's albedo and the
/// characteristic function `params` ask for; visibility = W's luminance, color = W, extra
/// "obscurance" = O. With in.cache, its scratch images are kept between calls.
MethodOutput run(const MethodInput& in, const TransferParams& params);
/// InputError when `params` ask for what the GPU path lacks (an analytic characteristic, two layers).
void check_gpu(const TransferParams& params);

}  // namespace ao
