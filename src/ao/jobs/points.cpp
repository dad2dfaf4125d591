// SPDX-License-Identifier: Apache-2.0
#include "ao/jobs/points.h"

#include <string>

#include "ao/core/error.h"
#include "ao/core/stopwatch.h"
#include "ao/jobs/fields.h"
#include "ao/jobs/provenance.h"
#include "ao/reference/ray_offset.h"
#include "ao/reference/ray_scene.h"

namespace ao {

namespace {

void check_points(const PointsRequest& r) {
  if (r.points.size() != r.normals.size())
    throw InputError(field(fields::kPointsNormals) + ": " + std::to_string(r.normals.size()) + " normals for " + std::to_string(r.points.size()) +
                     " points; give one per point");
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    const Vec3 p = r.points[i];
    if (!is_finite(p) || max_abs_coordinate(p) > kMaxCoordinate)
      throw InputError(field(fields::kPointsPoints) + ": point " + std::to_string(i) + " is not finite or lies beyond +-1e9");
    if (!is_finite(r.normals[i]) || !(length(r.normals[i]) > 0))
      throw InputError(field(fields::kPointsNormals) + ": normal " + std::to_string(i) + " is not a finite non-zero vector");
  }
  r.falloff.validate();
  r.params.validate();
}

}  // namespace

PointsResult run_points(const PointsRequest& r, const JobReporter& reporter) {
  check_points(r);
  Stopwatch clock;
  nlohmann::json timings;
  std::shared_ptr<const Scene> scene = r.scene.load();
  for (const std::string& w : scene->warnings) reporter.warn(w);
  timings["load_ms"] = clock.lap_ms();
  const PreparedScene prepared(scene, "ao occlusion", BvhOptions{});
  timings["bvh_ms"] = clock.lap_ms();
  PointsResult out;
  out.falloff = choose_falloff(r.falloff, prepared.radius_basis);
  const std::vector<VisibilityEstimate> e =
      estimate_visibility_at_points(*prepared.rays, r.points, r.normals, out.falloff, r.params, r.seed, reporter.start("occlusion"));
  timings["ao_ms"] = clock.lap_ms();
  std::uint64_t rays = 0;
  for (const VisibilityEstimate& v : e) {
    out.visibility.push_back(v.visibility);
    out.std_error.push_back(v.std_error);
    out.samples.push_back(v.samples);
    rays += static_cast<std::uint64_t>(v.samples);
  }
  out.summary = {{"ao", build_info()},
                 {"scene", scene->name},
                 {"points", r.points.size()},
                 {"membership", to_string(out.falloff.membership)},
                 {"radius", out.falloff.radius},
                 {"seed", r.seed},
                 {"parameters", r.params},
                 {"rays", rays},
                 {"timings", timings}};
  return out;
}

}  // namespace ao
