// SPDX-License-Identifier: Apache-2.0
// The deep G-buffer option of the screen-space methods (Mara, McGuire, Nowrouzezahrai and Luebke,
// "Deep G-Buffers for Stable Global Illumination Approximation", HPG 2016): a second depth layer,
// the nearest surface at least a minimum separation behind the visible one, so that the space
// hidden behind the first surface is no longer all taken for solid.
//
// How the methods read it (docs/methods/depth-layers.md): along a pixel's ray the solid is
//   one layer:                 [z1, infinity)                 (VAO fig. 2c)
//   second layer a back face:  [z1, infinity)                 (a closed solid: what lies past its far
//                                                              side is taken for solid, as with one layer)
//   second layer a front face: [z1, z1 + separation], [z2, infinity)
//   nothing behind:            [z1, z1 + separation]          (in both, the visible surface is a sheet,
//                                                              or thinner than the separation)
// Behind a sheet, the rest of the ray (the gap) is solid for a receiver x the sheet hides it from:
// x lies on the camera's side of the sheet's tangent plane at the point's pixel, and the segment
// from x to the point meets that plane where the sheet is (not past its rim).
// Containment, volumetric and ambient transfer test their points and pipes against that solid;
// Alchemy takes the second layer's point at each tap as an occluder too.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "ao/core/error.h"
#include "ao/core/gbuffer.h"
#include "ao/core/params.h"

namespace ao {

struct DepthLayers {
  int layers = 1;           ///< 1: the G-buffer's depth only; 2: also its second layer (GBuffer::second_depth).
  float separation = 0.0f;  ///< Minimum separation Delta of the second layer, world units; 0 = auto (kAutoSeparation x R).
};

/// The automatic minimum separation as a fraction of R (docs/methods/depth-layers.md measures it).
inline constexpr float kAutoSeparation = 0.25f;

/// The options' rows of a method's parameter table for a Params struct P that holds them in `member`:
/// layers, layer_separation.
template <class P>
std::vector<Param<P>> depth_layer_params(DepthLayers P::*member) {
  return {Param<P>::integer("layers", [member](P& p) -> int& { return (p.*member).layers; }, Range::closed(1, 2), "",
                            "depth layers: 1, the visible surface (everything behind it solid); 2, also the nearest surface at least "
                            "layer_separation behind it (a deep G-buffer, Mara et al. 2016)"),
          Param<P>::real("layer_separation", [member](P& p) -> float& { return (p.*member).separation; }, Range::at_least(0), "world units",
                         "minimum separation of the second layer; 0 = auto (R/4)")};
}

/// The separation in effect: `separation`, or kAutoSeparation x radius when it is 0.
inline float effective_separation(const DepthLayers& d, float radius) { return d.separation > 0 ? d.separation : kAutoSeparation * radius; }

/// Whether `g` carries a second layer rendered at `separation` (to a relative 1e-6).
inline bool has_second_layer(const GBuffer& g, float separation) {
  return !g.second_depth.empty() && g.second_depth.width() == g.width() && g.second_depth.height() == g.height() &&
         std::abs(g.second_separation - separation) <= 1e-6f * separation;
}

/// InputError for a method asked for two layers of a G-buffer that has none at `separation`.
[[noreturn]] inline void throw_missing_second_layer(const std::string& method, float separation) {
  throw InputError(method + ": layers=2 reads the G-buffer's second layer at separation " + std::to_string(separation) +
                   ", and this G-buffer has none there: render it from the scene (render_second_layer) or use layers=1");
}

}  // namespace ao
