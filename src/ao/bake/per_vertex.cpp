// SPDX-License-Identifier: Apache-2.0
// Outside-in per-vertex AO: for each direction, the z-buffer of ortho_raster.cpp (back faces
// culled) is a shadow map, and a vertex whose normal faces the direction is lit when its depth is
// within a bias of the stored depth at its pixel. Summing (w . n) over lit directions with weight
// 4/D estimates (1/pi) * integral over the hemisphere (eq. 1 of the per-texel AO paper).
//
// The bias: the vertex lies on the surface, but the z-buffer holds the depth at the pixel centre,
// up to half a pixel diagonal (0.71 px) away, where the surface is deeper by up to
// 0.71 px * tan(theta) for a surface tilted by theta from the view. We allow 1.5 px * tan(theta)
// (clamped at theta = 85 degrees) plus one pixel, so lit vertices are not self-shadowed; occluders
// closer than that to the surface are missed, which is the shadow-map method's known trade-off.
#include "ao/bake/per_vertex.h"

#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "ao/bake/ortho_raster.h"
#include "ao/core/error.h"
#include "ao/core/sampling.h"

namespace ao {

void VertexHistogramParams::validate() const {
  if (directions < 1 || directions > 65536) throw InputError("per-vertex histogram: directions must be in [1, 65536]");
  if (resolution < 64 || resolution > 8192) throw InputError("per-vertex histogram: resolution must be in [64, 8192]");
}

std::vector<float> bake_vertices_histogram(const Scene& scene, const VertexHistogramParams& params, const ProgressFn& progress) {
  params.validate();
  const RasterMesh mesh = make_raster_mesh(scene, 0, 0);
  const std::vector<Vec3> dirs = sphere_directions(params.direction_set, params.directions, params.seed);
  const float pixel_size = 2.0f * mesh.radius / static_cast<float>(params.resolution);
  const std::size_t nv = mesh.positions.size();
  struct Accum {
    std::vector<std::uint64_t> sum;
    RasterTarget target;
  };
  tbb::enumerable_thread_specific<Accum> accum;
  ProgressCounter counter(progress, dirs.size());
  constexpr double kScale = 1048576.0;  // fixed point, so the sum is the same in any order
  tbb::parallel_for(tbb::blocked_range<int>(0, static_cast<int>(dirs.size()), 1), [&](const tbb::blocked_range<int>& range) {
    Accum& acc = accum.local();
    if (acc.sum.empty()) acc.sum.assign(nv, 0);
    for (int d = range.begin(); d < range.end(); ++d) {
      const Vec3 w = dirs[static_cast<std::size_t>(d)];
      const std::uint32_t key = hash_combine(hash32(params.seed), static_cast<std::uint32_t>(d));
      const OrthoView view = make_ortho_view(mesh, w, pixel_size, {to_unit_float(hash_combine(key, 1)), to_unit_float(hash_combine(key, 2))});
      rasterize(mesh, view, acc.target);
      for (std::size_t v = 0; v < nv; ++v) {
        const float c = dot(w, mesh.normals[v]);
        if (c <= 0) continue;
        const int x = static_cast<int>(std::floor(acc.target.px[v])), y = static_cast<int>(std::floor(acc.target.py[v]));
        if (x < 0 || y < 0 || x >= view.width || y >= view.height) continue;
        const float tan_theta = std::sqrt(std::max(0.0f, 1 - c * c)) / std::max(c, 0.087f);
        const float bias = pixel_size * (1.0f + 1.5f * tan_theta);
        if (acc.target.pz[v] + bias < acc.target.depth(x, y)) continue;  // behind the shadow map
        acc.sum[v] += static_cast<std::uint64_t>(c * kScale + 0.5);
      }
      counter.add(1);
    }
  });
  std::vector<std::uint64_t> total(nv, 0);
  for (Accum& acc : accum)
    for (std::size_t v = 0; v < acc.sum.size(); ++v) total[v] += acc.sum[v];
  std::vector<float> out(nv);
  for (std::size_t v = 0; v < nv; ++v) out[v] = static_cast<float>(std::min(1.0, 4.0 / params.directions * static_cast<double>(total[v]) / kScale));
  return out;
}

}  // namespace ao
