// SPDX-License-Identifier: Apache-2.0
// Ray-traced ground truth: the obscurance integral of volumetric AO's eq. 2,
//   V(x) = (1/pi) * integral over the hemisphere about N of mu(D(w)) cos(theta) dw,
// estimated per pixel by Monte Carlo with cosine-weighted directions (pdf cos(theta)/pi, which
// cancels the integrand's cos(theta)/pi, so V is the plain mean of mu(D) over the samples).
// Every approximate method is judged against this with the same R and membership.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/membership.h"
#include "ao/core/params.h"
#include "ao/core/progress.h"
#include "ao/reference/ray_scene.h"

namespace ao {

struct RaytracedParams {
  int samples = 256;           ///< Rays per pixel; with target_error, the most a pixel may take. [1, 1048576].
  float target_error = 0.0f;   ///< Stop a pixel once the standard error of its mean is <= this; 0 = off. [0, 0.5].
  int min_samples = 64;        ///< With target_error: rays a pixel takes before it may stop. [16, samples].
  float offset = 0.0f;         ///< Ray origin offset along the geometric normal, world units, [0, kMaxCoordinate]; 0 = the scale-free offset of ray_offset.h.

  /// Throws InputError naming the bad field.
  void validate() const;
};
/// The parameter table (core/params.h): JSON keys, ranges, defaults, help.
const ParamTable<RaytracedParams>& raytraced_param_table();
void to_json(nlohmann::json& j, const RaytracedParams& p);
/// Rejects unknown keys, wrong types and values out of range with InputError.
void from_json(const nlohmann::json& j, RaytracedParams& p);

/// The estimate at one point.
struct VisibilityEstimate {
  float visibility = 1.0f;  ///< Mean of mu(D) over the samples, in [0, 1].
  float std_error = 0.0f;   ///< Standard error of that mean (sample standard deviation / sqrt(n)).
  int samples = 0;          ///< Rays traced.
};

/// V at world-space point p with unit normal n. `seed` keys the point's scrambled sample set.
VisibilityEstimate estimate_visibility(const RayScene& scene, Vec3 p, Vec3 n, const Falloff& falloff, const RaytracedParams& params,
                                       std::uint32_t seed);

/// V at many world-space points with unit normals (`points` and `normals` of the same length):
/// estimate_visibility at each, in parallel, point i with the sample set keyed by
/// pixel_seed(seed, i, 0), so the result does not depend on the thread count. Each ray starts off
/// its point along the point's normal (params.offset, or the scale-free offset of ray_offset.h).
std::vector<VisibilityEstimate> estimate_visibility_at_points(const RayScene& scene, std::span<const Vec3> points, std::span<const Vec3> normals,
                                                              const Falloff& falloff, const RaytracedParams& params, std::uint32_t seed,
                                                              const ProgressFn& progress = {});

struct RaytracedImage {
  Image<float> visibility;       ///< V per pixel; 1 where the G-buffer is not covered.
  Image<float> std_error;        ///< Standard error per pixel; 0 where not covered.
  double mean_std_error = 0.0;   ///< Over covered pixels.
  double max_std_error = 0.0;    ///< Over covered pixels.
  std::uint64_t rays = 0;        ///< Rays traced in all.
};

/// V for every covered pixel of `gbuffer`, whose camera must carry the world placement the
/// G-buffer was rendered with. Pixel (x, y) uses the sample set keyed by pixel_seed(seed, x, y),
/// so the result does not depend on the thread count.
RaytracedImage render_raytraced(const RayScene& scene, const GBuffer& gbuffer, const Falloff& falloff, const RaytracedParams& params,
                                std::uint32_t seed, const ProgressFn& progress = {});

}  // namespace ao
