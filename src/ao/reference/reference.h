// SPDX-License-Identifier: Apache-2.0
// The ray-traced references by kind: what `ao render -m raytraced -p reference=KIND` renders and
// what `ao compare` judges each method against (the registry's MethodInfo::reference says which).
//  - obscurance:     the obscurance integral of a membership (VAO eq. 2; raytraced.h);
//  - tangent-sphere: the visible fraction of the tangent sphere, volumetric AO's V (tangent_sphere.h);
//  - transfer:       ambient transfer W with the occluders' albedo (AT eq. 6; transfer_reference.h).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json_fwd.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/membership.h"
#include "ao/core/progress.h"
#include "ao/reference/ray_scene.h"
#include "ao/reference/raytraced.h"
#include "ao/reference/transfer_reference.h"

namespace ao {

enum class ReferenceKind {
  Obscurance,     ///< V = (1/pi) integral of mu(D) cos theta (VAO eq. 2), any membership.
  TangentSphere,  ///< Visible fraction of the tangent sphere of radius R/2 (VAO eq. 6-7); no membership.
  Transfer,       ///< Ambient transfer W (AT eq. 6), RGB; the scalar is its luminance.
};

/// "obscurance", "tangent-sphere", "transfer".
std::string_view to_string(ReferenceKind kind);
/// The kind called `name`; nullopt for anything else.
std::optional<ReferenceKind> parse_reference_kind(std::string_view name);
/// Comma-separated list of the kinds' names, for messages and --help.
std::string reference_kind_names();

/// A reference: its kind and the falloff it uses (R for every kind; the membership for Obscurance
/// and Transfer).
struct ReferenceSpec {
  ReferenceKind kind = ReferenceKind::Obscurance;
  Falloff falloff;
  float albedo_scale = 1.0f;  ///< Transfer only: multiplies the occluders' albedo, [0, 1].
  /// Transfer only: whose albedo the occluders reflect with (transfer_reference.h).
  TransferAlbedo albedo = TransferAlbedo::Occluders;

  /// Short name for tables and sheets: "step obscurance", "tangent sphere", "transfer (step)",
  /// "transfer (step, receiver albedo)".
  std::string label() const;
  /// Identifies the image: equal keys render the same reference.
  std::string key() const;
};
/// {"kind", "membership" (not for tangent-sphere), "radius", "tau"/"u" where the membership has
/// one, "albedo_scale" (transfer, when not 1), "albedo": "receiver" (transfer with the receiver's)}.
void to_json(nlohmann::json& j, const ReferenceSpec& r);

/// The obscurance reference of `f`, with Alchemy's falloff written as Step when it is Step (u >= R:
/// then mu = 0 below R and 1 beyond), so that tables name it as what it is.
ReferenceSpec obscurance_reference(Falloff f);

/// A rendered reference.
struct ReferenceImage {
  RaytracedImage scalar;  ///< V (transfer: the luminance of W), standard errors, rays.
  Image<Vec3> color;      ///< Transfer: W per channel; empty otherwise.
  Image<float> obscurance;  ///< Transfer: O from the same rays; empty otherwise.
};

/// Renders `spec` for every covered pixel of `gbuffer` (samples, adaptive stopping and offset from
/// `params`); the same seed gives the same image at any thread count.
ReferenceImage render_reference(const RayScene& scene, const GBuffer& gbuffer, const ReferenceSpec& spec, const RaytracedParams& params,
                                std::uint32_t seed, const ProgressFn& progress = {});

}  // namespace ao
