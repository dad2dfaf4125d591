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
// AT 4.3's silhouette elimination takes a surface more than R in front of a point for a distant
// foreground object with free space behind it. Where the second layer is a closed solid's exit
// (a closed mesh seen from outside: GBuffer::second_depth marks it) the ray is inside that solid
// up to z2, so [z1, z2] stays solid however far in front z1 is; the elimination frees only what
// lies past z2 (the ground under a sphere's bulge beside its contact sees the sphere's inside).
// Containment, volumetric and ambient transfer test their points and pipes against that solid;
// Alchemy takes the second layer's point at each tap as an occluder too; GTAO makes each sample a
// slab of that solid and counts the directions the slabs cover (a visibility bitmask).
//
// Without a second layer (one layer), `thickness` > 0 takes every visible surface for a sheet of
// that thickness with nothing behind it: the solid along a pixel's ray is [z1, z1 + thickness] and,
// beyond it, what the sheet hides from the receiver (the sheet test above). That is the second
// layer's reading where it finds nothing behind, at separation = thickness, for scenes made of open
// sheets whose second layer cannot be traced (a G-buffer file or arrays, the GPU backend); on closed
// solids it frees what lies behind their far side (docs/methods/depth-layers.md measures both).
#pragma once

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "ao/core/error.h"
#include "ao/core/gbuffer.h"
#include "ao/core/params.h"

namespace ao {

struct DepthLayers {
  int layers = 1;           ///< 1: the G-buffer's depth only; 2: also its second layer (GBuffer::second_depth).
  float separation = 0.0f;  ///< Minimum separation Delta of the second layer, world units; 0 = auto (kAutoSeparation x R).
  /// With one layer: 0, the solid behind the visible surface runs on without end (VAO fig. 2c);
  /// > 0, world units, the visible surface is a sheet this thick with nothing behind it (above).
  /// Only with layers = 1 (with two, the second layer says what lies behind).
  float thickness = 0.0f;
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

/// The `thickness` row of a method's parameter table (the methods that test points against the solid
/// behind the depth buffer: containment, volumetric, transfer; and GTAO, whose samples become slabs).
template <class P>
Param<P> thickness_param(DepthLayers P::*member) {
  return Param<P>::real("thickness", [member](P& p) -> float& { return (p.*member).thickness; }, Range::at_least(0), "world units",
                        "with layers=1: 0, everything behind the visible surface is solid; > 0, every visible surface is a sheet this thick "
                        "with nothing behind it (for scenes of open sheets without a second layer)");
}

/// The separation in effect: `separation`, or kAutoSeparation x radius when it is 0.
inline float effective_separation(const DepthLayers& d, float radius) { return d.separation > 0 ? d.separation : kAutoSeparation * radius; }

/// Whether the methods read a second layer: the G-buffer's (layers = 2) or one layer's sheets of
/// `thickness`, whose second layer holds nothing behind any pixel.
inline bool reads_second_layer(const DepthLayers& d) { return d.layers == 2 || d.thickness > 0; }

/// The separation the second layer is read at: the effective separation with two layers, the
/// thickness with one.
inline float layer_separation(const DepthLayers& d, float radius) { return d.layers == 2 ? effective_separation(d, radius) : d.thickness; }

/// The second layer of one layer's sheets: nothing (+infinity) behind every pixel of `g`.
inline std::shared_ptr<const Image<float>> nothing_behind(const GBuffer& g) {
  return std::make_shared<const Image<float>>(g.width(), g.height(), std::numeric_limits<float>::infinity());
}

/// InputError when `d` asks for a thickness with two layers, where the second layer says it.
inline void check_thickness(const DepthLayers& d, const std::string& method) {
  if (d.thickness > 0 && d.layers != 1)
    throw InputError(method + ": thickness is one layer's sheet model, and layers=2 reads what lies behind from the second layer (its "
                              "layer_separation is the sheets' thickness there): use one of them");
}

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
