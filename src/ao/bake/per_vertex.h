// SPDX-License-Identifier: Apache-2.0
// Per-vertex AO by the outside-in method: the per-texel AO paper's z-buffered renders from D
// directions (sec. 3), with each vertex tested against the z-buffer instead of scattered into a
// texture. (The ray-traced per-vertex baker is bake_vertices_raytraced in raytraced_bake.h.)
#pragma once

#include <vector>

#include "ao/bake/sphere_directions.h"
#include "ao/core/progress.h"
#include "ao/scene/mesh.h"

namespace ao {

struct VertexHistogramParams {
  int directions = 512;                                  ///< D, on the whole sphere. [1, 65536].
  DirectionSet direction_set = DirectionSet::Fibonacci;  ///< As HistogramParams.
  int resolution = 1024;                                 ///< View size in pixels across the bounding sphere. [64, 8192].
  std::uint32_t seed = 1;

  void validate() const;
};

/// V at each vertex of each mesh (concatenated in mesh order): (4/D) sum over directions w with
/// w . n > 0 in which the vertex is not behind the z-buffer, of w . n (the discrete eq. 1).
/// Unlimited distance, like the texel histogram baker.
std::vector<float> bake_vertices_histogram(const Scene& scene, const VertexHistogramParams& params, const ProgressFn& progress = {});

}  // namespace ao
