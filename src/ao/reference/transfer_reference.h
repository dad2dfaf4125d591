// SPDX-License-Identifier: Apache-2.0
// Ray-traced reference of ambient transfer (Umenhoffer, Toth, Szirmay-Kalos, "Efficient Methods for
// Ambient Lighting", AT): the transfer function W of eq. 6,
//
//   W(x) = integral of mu(d(w)) cos+ theta dw / (pi - integral of (1 - mu(d(w))) a(y(w)) cos+ theta dw)   per RGB channel
//
// with d(w) the distance to the first surface in direction w, y(w) that surface's point and a(y)
// its albedo. Eq. 6 is eq. 4's obscurance plus the light the occluders reflect, with their own W(y)
// taken equal to W(x), which sums every bounce between x and its neighbourhood as a geometric
// series. It is exactly the integral `transfer` (eq. 9) estimates with containment tests, here
// with rays: the hit point's true albedo instead of the albedo read at the first occluded test
// point's pixel, and the true distance instead of m tests per ray.
//
// Monte Carlo: cosine-weighted directions (pdf cos(theta)/pi) turn both integrals into means over
// the same samples, o_i = mu(d_i) and l_i = (1 - mu(d_i)) a(y_i), so W = mean(o) / (1 - mean(l));
// the same rays give the obscurance O = mean(o) (eq. 5). The ratio of means is the weighted
// importance estimate the method uses too; its standard error is the delta method's. The
// directions are those of render_raytraced for the same seed, so O equals the obscurance
// reference of the same membership. W = 0 where O = 0, as the method has it (no open direction,
// no sky light arrives). Derivation and choices: docs/methods/transfer.md#reference.
#pragma once

#include <cstdint>

#include "ao/core/gbuffer.h"
#include "ao/core/membership.h"
#include "ao/core/progress.h"
#include "ao/reference/ray_scene.h"
#include "ao/reference/raytraced.h"

namespace ao {

/// Whose albedo the light reflected between x and its neighbourhood takes in W.
enum class TransferAlbedo {
  Occluders,  ///< Each occluder's own (AT eq. 6 with a(y)): what `transfer` estimates.
  Receiver,   ///< The receiving point's (the G-buffer's albedo at its pixel) for every occluder:
              ///< the neighbourhood GTAO's multi-bounce fit assumes (Jimenez et al. 2016, sec. 5).
};

/// The estimate at one point.
struct TransferEstimate {
  Vec3 transfer{1.0f, 1.0f, 1.0f};  ///< W per RGB channel, in [0, 1].
  float luminance = 1.0f;           ///< Rec. 709 luminance of W.
  float obscurance = 1.0f;          ///< O, eq. 5, from the same rays.
  float std_error = 0.0f;           ///< Standard error of `luminance` (delta method, bounded by the channels' sum).
  int samples = 0;                  ///< Rays traced.
};

/// W at world point p with unit normal n, for `falloff`'s membership and R; the occluders' albedo
/// (each mesh's Mesh::albedo, by the hit's geometry) is multiplied by `albedo_scale` in [0, 1], as
/// the method's albedo_scale does. `params` as for estimate_visibility; with a target error the
/// luminance's standard error decides.
TransferEstimate estimate_transfer(const RayScene& scene, Vec3 p, Vec3 n, const Falloff& falloff, float albedo_scale,
                                   const RaytracedParams& params, std::uint32_t seed);

struct TransferReferenceImage {
  Image<Vec3> transfer;    ///< W per channel; 1 where not covered.
  RaytracedImage scalar;   ///< Luminance of W as `visibility`, its standard errors and ray count.
  Image<float> obscurance; ///< O; 1 where not covered.
};

/// The same for every covered pixel of `gbuffer`, pixel (x, y) keyed by pixel_seed(seed, x, y).
/// With TransferAlbedo::Receiver every occluder takes the pixel's G-buffer albedo (times
/// `albedo_scale`); InputError when the G-buffer has no albedo.
TransferReferenceImage render_transfer_reference(const RayScene& scene, const GBuffer& gbuffer, const Falloff& falloff, float albedo_scale,
                                                 const RaytracedParams& params, std::uint32_t seed, const ProgressFn& progress = {},
                                                 TransferAlbedo albedo = TransferAlbedo::Occluders);

}  // namespace ao
