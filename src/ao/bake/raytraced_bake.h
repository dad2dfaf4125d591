// SPDX-License-Identifier: Apache-2.0
// Inside-out AO map baking with Embree: per texel, rays from points spread over the texel's patch
// of surface. The reference for the histogram baker, and the baker to use when occluders should
// only count within a distance R (the histogram baker's distance is unlimited).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/bake/bake_result.h"
#include "ao/bake/texel_coverage.h"
#include "ao/core/gbuffer.h"
#include "ao/core/membership.h"
#include "ao/core/params.h"
#include "ao/core/progress.h"
#include "ao/reference/ray_scene.h"

namespace ao {

/// Which side of the surface a bake's rays leave to (RaytracedBakeParams::hemisphere).
enum class Hemisphere { Outside, Inside };

/// Where a map's rays start within each texel (RaytracedBakeParams::texel_sampling).
enum class TexelSampling { Area, Centre };

struct RaytracedBakeParams {
  int samples = 64;                      ///< Rays per texel (or vertex), each from its own point of the patch. [1, 1048576]. 64: the fewest that bake refined_elephant_uv at 1024^2 within RMSE 0.02 of a 1024-ray bake (docs/methods/bake.md).
  std::optional<float> max_distance;     ///< R, world units, > 0; nullopt = unlimited distance (the paper's eq. 1).
  Membership membership = Membership::Step;  ///< mu(d) when max_distance is set; unlimited distance is a step at infinity.
  float offset = 0.0f;                   ///< Ray origin offset along the face normal, world units, [0, kMaxCoordinate]; 0 = the scale-free offset of reference/ray_offset.h.
  bool ignore_back_faces = false;        ///< Rays pass through back faces (what xNormal's and Substance's "ignore backface" do).
  /// The hemisphere each point integrates over. Shading (default, as the G-buffer's): about the
  /// interpolated vertex normal, the smooth surface the mesh stands for. Geometric: about the face
  /// normal of the triangle the point lies on; at a vertex (per-vertex bakes), the area-weighted
  /// mean over the vertex's triangles of the integral about each face normal.
  SurfaceNormal normal = SurfaceNormal::Shading;
  bool bent_normals = false;             ///< Also average the unoccluded directions per texel.
  /// The full angle, degrees, of the cone of directions about the normal that each point
  /// integrates over: (0, 180], 180 = the hemisphere. V is the cosine-weighted mean of mu over the
  /// cone, (1 / (pi sin^2(a/2))) * integral over the cone of mu cos dw: narrower cones darken only
  /// what lies straight ahead (Substance's and Marmoset's "spread angle").
  float spread_angle = 180.0f;
  /// max_distance is a fraction of the diagonal of the baked meshes' bounding box (the meshes with
  /// UVs, or every mesh of a per-vertex bake of meshes without; occluders and the floor excluded), so
  /// one setting suits models of any scale. [Needs max_distance.]
  bool relative_distance = false;
  /// Outside (default): the hemisphere above the surface, AO. Inside: the one below it, rays into
  /// the mesh from points pushed in along the face normal, back faces hit like any other (the
  /// inside of a closed mesh is its back faces): with a distance R, a thickness map, 1 where nothing
  /// of the mesh lies within R behind the point, darker the thinner the mesh there.
  Hemisphere hemisphere = Hemisphere::Outside;
  /// Maps only. Area (default): each ray from its own point of the texel's patch of surface, so a
  /// texel holds the mean of V over the surface it covers (what a filtered texture lookup of it
  /// returns). Centre: every ray from the one surface point under the texel's centre (the nearest
  /// point of its patch when the centre is off the chart), point sampling as Cycles and most bakers
  /// rasterize the UVs; where V changes within a texel (contacts, creases) the two differ.
  TexelSampling texel_sampling = TexelSampling::Area;
  std::uint32_t seed = 1;                ///< Keys the sample sets (one sequence per 4 x 4 block of texels; per vertex).
  /// Maps only: sigma, in texels, of the texture-space filter that averages the noise of texels
  /// that are neighbours on the surface (denoise.h); 0 = off, the plain estimate of eq. 2.
  /// [0, kMaxDenoiseSigma]. Bent normals are not filtered. 0 here, where this baker is a building
  /// block; run_bake (jobs/bake.h), the one call that bakes as `ao bake` does, uses
  /// kDefaultBakeDenoise.
  float denoise = 0.0f;

  /// Throws InputError naming the bad field.
  void validate() const;
  /// The falloff actually used; for unlimited distance, a Step whose reach is +infinity.
  /// max_distance as given: resolve a relative one first (with_absolute_distance).
  Falloff falloff() const;
  /// These settings with a relative max_distance made absolute for baked meshes whose bounding
  /// box is `baked` (unchanged when relative_distance is off).
  RaytracedBakeParams with_absolute_distance(const Bounds3& baked) const;
};
void to_json(nlohmann::json& j, const RaytracedBakeParams& p);
void from_json(const nlohmann::json& j, RaytracedBakeParams& p);
/// The ray-traced baker's parameter table (core/params.h): JSON in and out, validate(), the CLI's
/// help and the docs come from it.
const ParamTable<RaytracedBakeParams>& raytraced_bake_param_table();

/// Triangles above which a ray-traced bake builds a Medium BVH (binned SAH) instead of a High one
/// (SAH with spatial splits). The spatial splits pay off on long thin triangles, the stuff of
/// low-poly meshes, whose High build is quick; on a dense mesh they cost build time and gain no
/// speed: on refined_elephant_uv (88,928 triangles) the High build took 0.2 s of a 1.5 s bake at
/// 1024^2 and 64 rays, and the rays traced no faster than through the Medium BVH (BENCHMARKS.md,
/// "bake").
inline constexpr std::size_t kBakeMediumBvhTriangles = 50'000;
/// The BVH settings for ray-traced bakes of a scene of `triangles` triangles: quads of paired
/// triangles, Medium above kBakeMediumBvhTriangles (the rest chosen as RayScene does).
inline BvhOptions bake_bvh_options(std::size_t triangles) {
  BvhOptions o;
  if (triangles > kBakeMediumBvhTriangles) o.quality = BvhQuality::Medium;
  // Quads: half the primitives, about 1.07x faster bakes of refined_elephant_uv (docs/methods/bake.md,
  // "Speed"). Not above kCompactBvhTriangles, where the BVH is compact for memory: compact quads
  // traced slower than the Medium quads (0.87x), and pairing takes about 100 bytes per triangle
  // while the BVH is built.
  o.quads = triangles <= kCompactBvhTriangles;
  return o;
}

/// The bounding box of `scene`'s meshes with UVs: the meshes a bake bakes (occluders have none);
/// of every mesh when none has UVs (a per-vertex bake).
Bounds3 baked_bounds(const Scene& scene);

/// V per covered texel, the area-weighted mean of the obscurance integral over the texel's patch
/// (eq. 2 of the per-texel AO paper, with mu(D) in place of V when R is set). Sample i of texel
/// (x, y) takes its cosine-weighted direction and its point from point i of one 4-D Owen-scrambled
/// Sobol set keyed by pixel_seed(seed, x, y) (direction and point jointly stratified):
/// deterministic at any thread count.
/// Rays whose direction lies below the face (possible with smooth normals) count as occluded.
BakeResult bake_raytraced(const RayScene& rays, const TexelCoverage& coverage, const RaytracedBakeParams& params,
                          const ProgressFn& progress = {});

/// V at each vertex of each mesh (concatenated in mesh order), from the vertex along its normal.
std::vector<float> bake_vertices_raytraced(const RayScene& rays, const RaytracedBakeParams& params, std::uint64_t* rays_traced = nullptr,
                                           const ProgressFn& progress = {});

}  // namespace ao
