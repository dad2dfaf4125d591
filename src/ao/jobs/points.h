// SPDX-License-Identifier: Apache-2.0
// AO at points the caller chooses: the ray-traced reference's estimator (reference/raytraced.h,
// the obscurance integral of volumetric AO's eq. 2 with cosine-weighted Sobol directions) at
// world-space points and normals, with the scene, falloff and seed of a render, and the standard
// error of each estimate. What libigl's ambient_occlusion offers, with ao's estimator; `ao.occlusion`
// in Python.
//
//   PointsRequest r;
//   r.scene.args = {"mesh.obj"};
//   r.points = {{0, 0.01f, 0}};
//   r.normals = {{0, 1, 0}};
//   const PointsResult out = run_points(r);   // out.visibility[0], out.std_error[0]
#pragma once

#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/math.h"
#include "ao/core/membership.h"
#include "ao/jobs/inputs.h"
#include "ao/jobs/reporter.h"
#include "ao/reference/raytraced.h"

namespace ao {

struct PointsRequest {
  SceneSource scene;
  std::vector<Vec3> points;   ///< World units, finite, within +-kMaxCoordinate.
  std::vector<Vec3> normals;  ///< One per point: the hemisphere's axis; finite and non-zero (normalised here).
  FalloffRequest falloff;     ///< R default: radius_fraction x the objects' diagonal, as for a render.
  RaytracedParams params;     ///< samples (default 256), target_error, min_samples, offset.
  std::uint32_t seed = 1;     ///< Point i uses the sample set keyed by pixel_seed(seed, i, 0).
};

struct PointsResult {
  std::vector<float> visibility;  ///< V in [0, 1] per point.
  std::vector<float> std_error;   ///< Standard error of each V (sample standard deviation / sqrt(n)).
  std::vector<int> samples;       ///< Rays traced per point.
  Falloff falloff;                ///< R and membership used.
  nlohmann::json summary;         ///< {"ao", "scene", "points", "radius", "membership", "parameters", "rays", "timings", ...}.
};

/// Checks the points and normals (InputError naming the first bad one), loads the scene, builds
/// its BVH and estimates V at every point (estimate_visibility_at_points).
PointsResult run_points(const PointsRequest& request, const JobReporter& reporter = {});

}  // namespace ao
