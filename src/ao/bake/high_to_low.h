// SPDX-License-Identifier: Apache-2.0
// High-to-low baking, as xNormal, Substance and Marmoset do it: the AO of a detailed (high-poly)
// mesh transferred into the UV layout of a simple (low-poly) mesh. For each sample point p of a
// texel's patch on the low mesh, a ray leaves the cage (the low mesh pushed outwards along its
// smoothed normals, or an explicit cage mesh of the same topology) and travels inwards through p;
// its first hit on a front face of the high mesh is where AO is computed, with the high mesh's
// normal, against the high mesh and any extra occluders. The low mesh itself never occludes.
#pragma once

#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/bake/bake_result.h"
#include "ao/bake/raytraced_bake.h"
#include "ao/bake/texel_coverage.h"
#include "ao/core/progress.h"
#include "ao/reference/ray_scene.h"

namespace ao {

/// Default cage extrusion as a fraction of the low mesh's bounding-box diagonal (Substance's
/// default frontal and rear distances, 0.01 of the bounding box).
inline constexpr float kDefaultCageFraction = 0.01f;

struct HighToLowParams {
  RaytracedBakeParams ao;               ///< The AO at the high-poly hit: samples (rays per texel), distance, membership, offset, back faces, seed.
  std::optional<float> cage_extrusion;  ///< D, world units, >= 0: cage = low vertex + D x smoothed normal; nullopt = fitted_cage_extrusion (the bake job). Ignored with an explicit cage.
  std::optional<float> max_front;       ///< How far outside the low surface a ray starts, world units, >= 0; nullopt = at the cage.
  std::optional<float> max_back;        ///< How far inside the low surface a ray still looks for the high mesh, world units, >= 0; nullopt = the cage distance at that point.
  /// Cage rays per texel, [1, 1048576], at most ao.samples of them used: stratified points of the
  /// texel's low patch, each carrying an equal share of the texel's AO directions (a stratum of its
  /// hemisphere set) from where its cage ray meets the high mesh; >= ao.samples = one cage ray per
  /// sample. 4: on refined_elephant onto a 4,446-triangle decimation at 64 rays the map's RMSE
  /// against a converged bake is that of a cage ray per sample (0.0184 against 0.0183; 1 point:
  /// 0.0194) for 1.06x the CPU of a single-mesh bake instead of 2.3x (docs/methods/bake.md, "High
  /// to low").
  int cage_points = 4;

  /// Throws InputError naming the bad field.
  void validate() const;
};
void to_json(nlohmann::json& j, const HighToLowParams& p);
void from_json(const nlohmann::json& j, HighToLowParams& p);
/// The high-to-low parameter table: the ray-traced baker's rows (for the AO at the high-poly hit),
/// then the cage's.
const ParamTable<HighToLowParams>& high_to_low_param_table();

/// The BVH settings for high-to-low targets of `triangles` triangles: triangles (the cage rays' hits
/// are interpolated with Embree's triangle barycentrics), Medium above kBakeMediumBvhTriangles as
/// for bakes. A few cage rays per texel do not repay the High build's spatial splits; the AO rays go
/// to an occluder scene built with bake_bvh_options (quads), which may hold the same meshes.
inline BvhOptions high_to_low_target_bvh_options(std::size_t triangles) {
  BvhOptions o = bake_bvh_options(triangles);
  o.quads = false;
  return o;
}

/// Per low mesh, the cage position of each vertex.
using CagePositions = std::vector<std::vector<Vec3>>;

/// Per low mesh, the smoothed normal of each vertex: the normals of all vertices at its position
/// (hard edges and UV seams split vertices) summed and normalised; the direction extrude_cage pushes.
std::vector<std::vector<Vec3>> smoothed_vertex_normals(const Scene& low);

/// The cage extrusion D, world units, that lets cage rays reach the high meshes `targets` from
/// about 99% of the low surface's area: the area-weighted 99th percentile, over four points per
/// low triangle, of the distance along the smoothed normal (outwards or inwards, whichever is
/// nearer) to the first high face, times 1.05; at least kDefaultCageFraction and at most 0.1 of
/// the low diagonal (cage_fit.cpp). The default of a bake without a cage or an extrusion.
float fitted_cage_extrusion(const Scene& low, const RayScene& targets);

/// The low meshes' vertices pushed out by `distance` along their smoothed normals: the normals of
/// all vertices at one position (hard edges and UV seams split vertices) averaged, so the cage
/// does not tear open at hard edges.
CagePositions extrude_cage(const Scene& low, float distance);

/// The vertex positions of `cage`, which must have the low scene's topology: the same meshes with
/// the same vertex counts and triangle indices. Throws InputError naming `cage.name` otherwise.
CagePositions cage_from_mesh(const Scene& low, const Scene& cage);

/// V per covered texel of `coverage` (computed on `low`): the mean over `params.ao.samples`
/// samples per texel, split evenly among `params.cage_points` stratified points of the texel's
/// patch; each point's cage ray to `targets` (the high meshes, a RayScene of triangles: built
/// without BvhOptions::quads, since the cage ray's hit is interpolated with Embree's triangle
/// barycentrics) and its share of cosine-weighted AO rays from the hit, traced in `occluders` (the
/// high meshes and any extra occluders; may be the same RayScene as `targets`; either kind). The
/// samples of a point whose cage ray misses are left out of the mean; a texel where all miss is marked in BakeResult::missed, counted in
/// missed_texels, and takes the value of the nearest texel that hit (fill_missed_texels).
/// Deterministic at any thread count (per-texel scrambled Sobol sets, as bake_raytraced).
BakeResult bake_high_to_low(const Scene& low, const TexelCoverage& coverage, const CagePositions& cage, const RayScene& targets,
                            const RayScene& occluders, const HighToLowParams& params, const ProgressFn& progress = {});

/// Gives every missed texel the value of the nearest covered texel that was not missed (within 64
/// texels; beyond that, the mean V of the map), so misses look like their surroundings instead of
/// black. Bent normals are filled the same way.
void fill_missed_texels(BakeResult& result);

}  // namespace ao
