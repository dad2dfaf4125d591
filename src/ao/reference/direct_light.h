// SPDX-License-Identifier: Apache-2.0
// The direct-light pass for scenes `ao` renders itself: a sun (directional light) with shadow
// rays, giving the radiance Ld that ambient transfer's radiance mode reads at occluders (AT sec.
// 4.1, the sentence after eq. 9; docs/methods/transfer.md) and that shading adds to a W La.
//
// For a diffuse surface of albedo a (BRDF a/pi) lit by a directional light of irradiance E
// (measured on a surface facing the light) from direction l:
//
//   Ld(x) = a(x)/pi * E * max(0, n.l) * visible(x, l)
//
// E is in units of the ambient radiance La, so Ld is too. An open horizontal surface receives
// pi La from the whole sky, so E = pi is a sun that lights a surface facing it as much as the sky
// does, and gives an unshadowed white surface facing the sun Ld = 1 = La.
#pragma once

#include "ao/core/gbuffer.h"
#include "ao/core/math.h"
#include "ao/core/progress.h"
#include "ao/reference/ray_scene.h"

namespace ao {

struct Sun {
  Vec3 direction{0.0f, 1.0f, 0.0f};  ///< World space, pointing TOWARDS the sun; unit length.
  float irradiance = kPi;            ///< E on a surface facing the sun, in units of La; finite, >= 0. pi: as bright as the sky.

  /// Throws InputError naming the bad field (direction not finite or not of unit length to 1e-3,
  /// irradiance negative or not finite).
  void validate() const;
};

/// Ld per pixel of `g` (whose camera must carry its world placement, as render_gbuffer's does):
/// one shadow ray per covered pixel facing the sun (n.l > 0, n the G-buffer's normal), from the
/// world position moved off its triangle by the robust offset of ray_offset.h (as the ray-traced
/// reference starts its rays). A sun below the triangle's own plane counts as shadowed. 0 where
/// not covered, facing away, or shadowed.
/// Deterministic and independent of the thread count (no sampling).
Image<Vec3> render_direct_light(const RayScene& scene, const GBuffer& g, const Sun& sun, const ProgressFn& progress = {});

}  // namespace ao
