// SPDX-License-Identifier: Apache-2.0
// Ground-truth-based ambient occlusion (GTAO). Based on Jimenez, Wu, Pesce, Jarabo, "Practical
// Realtime Strategies for Accurate Indirect Occlusion" (Activision tech. memo ATVI-TR-16-01,
// SIGGRAPH 2016 course). The paper is not in the project's papers folder; its equations are cited
// here by number where the number is certain (eq. 1) and otherwise by the part of the paper:
//
//   A(x) = (1/pi) int_H V(w) (n . w)+ dw                                                 (eq. 1)
//   horizon form, slices through the view vector w_o at screen angles phi:
//   A(x) = (1/pi) int_0^pi int_{h1(phi)}^{h2(phi)} cos(theta - gamma)+ |sin theta| dtheta dphi
//        = (1/pi) int_0^pi |n_p(phi)| a(phi) dphi
//   analytic inner integral ("GTAO: the inner integral"):
//   a(phi) = 1/4 (-cos(2 h1 - gamma) + cos gamma + 2 h1 sin gamma)
//          + 1/4 (-cos(2 h2 - gamma) + cos gamma + 2 h2 sin gamma)
//   with the horizons clamped to the hemisphere of the projected normal:
//   h1 = gamma + max(-theta1 - gamma, -pi/2), h2 = gamma + min(theta2 - gamma, pi/2)
//   multi-bounce fit ("Multi-bounce approximation", a cubic fitted to path-traced references):
//   V'(V, rho) = max(V, ((a V + b) V + c) V), a = 2.0404 rho - 0.3324,
//                b = -4.7951 rho + 0.6417, c = 2.7552 rho + 0.6903
//
// theta is the angle in the slice plane (through w_o and the screen direction phi) from w_o;
// theta1, theta2 the horizon angles found by marching the depth buffer on both sides; n_p the normal
// projected onto the slice plane, gamma its angle from w_o. The paper's A is already visibility
// (1 = open): V = A. With the radius cut (samples farther than R from x are ignored) GTAO estimates
// the cosine-weighted visibility within R, i.e. the obscurance of the volumetric AO paper's eq. 2
// with the step membership and the same R: its reference in the registry. docs/methods/gtao.md maps
// every symbol and lists the deviations.
//
// With a second depth layer or a thickness (`layers`), each sample is a slab of finite depth
// instead of the top of an endless solid, and a slice's inner integral is the open one times the
// fraction of 32 points, equal shares of it, that no slab covers within R: the visibility bitmask
// of Therrien, Levesque and Gilet ("Screen Space Indirect Lighting with Visibility Bitmask", 2023),
// its points spread in the inner integral's measure (gtao_kernel.cpp).
#pragma once

#include <cstdint>

#include <nlohmann/json_fwd.hpp>

#include "ao/core/gbuffer.h"
#include "ao/methods/depth_layers.h"
#include "ao/methods/filters/interleave.h"
#include "ao/methods/method.h"

namespace ao {

struct GtaoParams {
  int slices = 2;         ///< Slice directions per pixel (the outer integral over phi), [1, 16]. The 4x4 pattern and filter give 16x as many per 4x4 block.
  int steps = 8;          ///< Depth-buffer samples on each side of a slice (the horizon search), [1, 32].
  float step_power = 1;   ///< Samples lie at ((j + u) / steps)^step_power of the screen radius, [1, 4]: > 1 puts more of them near x
                          ///< (XeGTAO uses 2); 1 measured best against the step reference, whose horizon is set at distance R.
  bool multi_bounce = false;  ///< The multi-bounce fit with the G-buffer albedo; off: V is the visibility integral itself.
  InterleaveOptions interleave;  ///< 4x4 pattern of slice rotations and step offsets; the paper's 4x4 spatial denoiser (filter).
  /// How thick the surfaces behind the samples are (depth_layers.h). Default (one layer, thickness 0): every sample is the top
  /// of a solid running on without end, the paper's horizon form. A thickness or a second layer makes each sample a slab of
  /// finite depth, and the slice's occluded directions the union of the slabs' (a visibility bitmask; docs/methods/gtao.md).
  DepthLayers layers;

  /// Throws InputError naming the bad field.
  void validate() const;
};
/// The parameter table (core/params.h): JSON keys, ranges, defaults, help.
const ParamTable<GtaoParams>& gtao_param_table();
void to_json(nlohmann::json& j, const GtaoParams& p);
/// Rejects unknown keys, wrong types and values out of range with InputError.
void from_json(const nlohmann::json& j, GtaoParams& p);

struct GtaoImage {
  Image<float> visibility;  ///< V in [0,1]; 1 where not covered. With multi_bounce: the fit with rho = luminance of the albedo.
  Image<Vec3> color;        ///< With multi_bounce: the fit per RGB channel of the albedo; empty otherwise.
};

/// GTAO for every covered pixel with radius R = `radius` (world units, > 0). Deterministic for a
/// seed, independent of the thread count. With layers = 2 it reads g.second_depth, which must have
/// been rendered at the effective separation (InputError otherwise).
GtaoImage gtao_ao(const GBuffer& g, float radius, const GtaoParams& params, std::uint32_t seed);
/// The same with the second depth layer given apart (layers = 2; ignored with one layer).
GtaoImage gtao_ao(const GBuffer& g, const Image<float>* second_layer, float radius, const GtaoParams& params, std::uint32_t seed);

/// The multi-bounce fit: the multi-bounce visibility for visibility v and albedo rho (both in [0, 1]).
float gtao_multi_bounce(float v, float rho);

/// The method as the registry runs it (method.h): gtao_ao with R = in.falloff.radius.
MethodOutput run(const MethodInput& in, const GtaoParams& params);

/// InputError for what the GPU shader does not run: slabs (a thickness or a second layer).
void check_gpu(const GtaoParams& params);

}  // namespace ao
