// SPDX-License-Identifier: Apache-2.0
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

#include <nlohmann/json_fwd.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/image.h"
#include "ao/core/params.h"

namespace ao {

/// The most taps per 1-D pass.
inline constexpr int kMaxBilateralTaps = 63;

struct BilateralParams {
  int taps = 13;               ///< Taps per 1-D pass, odd, in [1, 63]. Paper: 13 (Figure 6, Table 1). 1 = no filtering.
  float spatial_sigma = 0.0f;  ///< Gaussian standard deviation across taps, pixels, >= 0; 0 selects taps / 4 (3.25 for 13).
  float plane_sigma = 0.01f;   ///< Tangent-plane distance scale, as a fraction of the centre's depth, > 0. Default 1%:
                               ///< wide enough for curved surfaces at the tap spacing, narrow enough to stop at creases.

  /// Throws InputError naming the bad field.
  void validate() const;
  float effective_spatial_sigma() const { return spatial_sigma > 0 ? spatial_sigma : static_cast<float>(taps) / 4.0f; }
};
/// The parameter table (core/params.h): JSON keys, ranges, defaults, help.
const ParamTable<BilateralParams>& bilateral_param_table();
void to_json(nlohmann::json& j, const BilateralParams& p);
/// Rejects unknown keys, wrong types and values out of range with InputError.
void from_json(const nlohmann::json& j, BilateralParams& p);

/// The filter's rows of a parameter table for a struct P that holds a BilateralParams, reached by
/// `ref` (a function P& -> BilateralParams&), with keys prefixed by `prefix` (alchemy: "filter_").
template <class P, class Ref>
std::vector<Param<P>> bilateral_params(const std::string& prefix, Ref ref) {
  return {Param<P>::integer(prefix + "taps", [ref](P& p) -> int& { return ref(p).taps; }, Range::closed(1, kMaxBilateralTaps), "",
                            "taps per 1-D pass, odd; 1 = no filtering (paper: 13)"),
          Param<P>::real(prefix + "spatial_sigma", [ref](P& p) -> float& { return ref(p).spatial_sigma; }, Range::at_least(0), "pixels",
                         "Gaussian standard deviation across taps; 0 = taps / 4"),
          Param<P>::real(prefix + "plane_sigma", [ref](P& p) -> float& { return ref(p).plane_sigma; }, Range::above(0), "",
                         "tangent-plane distance scale, as a fraction of the centre's depth")};
}

/// Filters `values` (one per G-buffer pixel; same size as `gbuffer`, InputError otherwise) in place
/// with a horizontal then a vertical pass. Tiles run in parallel; the result does not depend on the
/// thread count.
void bilateral_filter(const GBuffer& gbuffer, Image<float>& values, const BilateralParams& params);
/// The same with the G-buffer's depth_plane() already at hand (`depth`, same size), for a caller
/// that built it for its own pass.
void bilateral_filter(const GBuffer& gbuffer, const Image<float>& depth, Image<float>& values, const BilateralParams& params);

}  // namespace ao
