// Separable cross-bilateral filter, based on McGuire, Osman, Bukowski, Hennessy, "The Alchemy
// Screen-Space Ambient Obscurance Algorithm" (HPG 2011), sec. 2 (Listing 1, pass 5) and Figure 6:
// "two 13-tap 1D cross-bilateral filter passes" over the obscurance buffer, weighted by camera-space
// proximity to the surface being shaded. The paper gives no weight formula; ours (a deviation made
// explicit, docs/methods/alchemy.md):
//
//   w(j) = G(j; spatial_sigma) * K(|n_C . (P_j - C)| / plane_sigma(C))
//
// where G is a Gaussian in taps, C and n_C the centre pixel's camera-space position and normal,
// P_j the tap's position, and K(x) = max(0, 1 - x^2 / 4)^2 (a compact, smooth stand-in for a
// Gaussian of standard deviation ~1 that needs no exp, so the taps vectorise). Distance to the
// centre's tangent plane, rather than depth difference, keeps weights high along a plane seen at a
// grazing angle and drops them across creases and silhouettes. Background taps get weight 0;
// background pixels keep their value. Positions are reconstructed as depth * (camera ray through the
// pixel centre), so a tap reads one float of depth rather than a 12-byte position.
#pragma once

#include <cstdint>

#include <nlohmann/json.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/image.h"

namespace ao {

struct BilateralParams {
  int taps = 13;               ///< Taps per 1-D pass, odd, in [1, 63]. Paper: 13 (Figure 6, Table 1). 1 = no filtering.
  float spatial_sigma = 0.0f;  ///< Gaussian standard deviation across taps, pixels, >= 0; 0 selects taps / 4 (3.25 for 13).
  float plane_sigma = 0.01f;   ///< Tangent-plane distance scale, as a fraction of the centre's depth, > 0. Default 1%:
                               ///< wide enough for curved surfaces at the tap spacing, narrow enough to stop at creases.

  /// Throws InputError naming the bad field.
  void validate() const;
  float effective_spatial_sigma() const { return spatial_sigma > 0 ? spatial_sigma : static_cast<float>(taps) / 4.0f; }
};
void to_json(nlohmann::json& j, const BilateralParams& p);
/// Rejects unknown keys and wrong types with InputError.
void from_json(const nlohmann::json& j, BilateralParams& p);

/// Filters `values` (one per G-buffer pixel; same size as `gbuffer`, InputError otherwise) in place
/// with a horizontal then a vertical pass. Tiles run in parallel; the result does not depend on the
/// thread count.
void bilateral_filter(const GBuffer& gbuffer, Image<float>& values, const BilateralParams& params);

}  // namespace ao
