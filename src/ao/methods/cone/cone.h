// SPDX-License-Identifier: Apache-2.0
// Voxel cone traced ambient occlusion, based on E. C. Dalla Favera and W. Celes, "Ambient
// occlusion using cone tracing with scene voxelization", SIBGRAPI 2012.
//
// Per pixel, the hemisphere about the normal is sampled by cones (sec. III-C, Fig. 5a); each cone
// is sampled by a chain of spheres, tangent to each other and inscribed in the cone out to the
// distance of influence R_max (Fig. 5b); each sphere's obstructed volume is estimated from prisms
// along the grid's z through Poisson-disk samples of its great disk, counting solid voxels with
// masks and popcount (sec. III-C1, Figs. 6-7); spheres combine front to back,
// T *= (1 - occluded_k) (sec. III-C2, Fig. 8); cones are averaged.
//
// Convention: the paper computes the blocked fraction (occlusion); we return visibility
// V = mean over cones of T, 1 = fully open, which is 1 - the paper's occlusion.
// The reference this approximates is classical AO (membership `step`, R = R_max), cosine-weighted
// by default (the cones are placed in cells of equal cosine-weighted measure).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/params.h"
#include "ao/core/progress.h"
#include "ao/methods/cone/voxelize.h"
#include "ao/methods/method.h"

namespace ao {

namespace cone_internal {
struct SideSetup;
}

/// The paper's quality settings (Table I).
enum class ConeQuality { Low, Medium, High };

/// How cone directions are laid out over the hemisphere (always regularly in spherical coordinates).
enum class ConeWeighting {
  Cosine,   ///< Cells of equal cosine-weighted measure: the plain mean estimates classical AO (default).
  Uniform,  ///< Cells of equal solid angle: the plain mean is the unweighted hemisphere average.
};

struct ConeParams {
  ConeQuality preset = ConeQuality::Medium;  ///< Table I; fills cones/spheres/prisms left unset.
  std::optional<int> cones;    ///< Cones per pixel; unset (JSON null) = from the preset (6). [1, 64].
  std::optional<int> spheres;  ///< Spheres per cone; unset = from the preset (3/5/7). [1, 16].
  std::optional<int> prisms;   ///< Prisms per sphere; unset = from the preset (3/6/12). [1, 64].
  float aperture_deg = 30;   ///< Full apex angle of each cone, degrees (sec. III-C: 30). (0, 90).
  int depth_bits = 128;      ///< Voxels per grid column, multiple of 32 in [32, 1024]. Paper: 128.
  int columns = 512;         ///< Grid columns per side (world) or along the longer image side (eye). [8, 4096].
  GridSpace grid = GridSpace::World;               ///< "world" (default) or the paper's "eye".
  ConeWeighting weighting = ConeWeighting::Cosine; ///< "cosine" (default) or "uniform".
  OpenMeshes open_meshes = OpenMeshes::Winding;    ///< "winding" (default: by what each mesh is), "slab" or "parity" (the paper); voxelize.h.
  float slab_fraction = 1.0f;  ///< Thickness of the slab behind open meshes, as a fraction of R_max. (0, 16].
  bool jitter = true;        ///< Per pixel: each cone's axis at a random point of its cell, a random scale of its
                             ///< sphere chain, a random turn of the prism pattern (noise instead of rings). false: the paper's fixed pattern.
  int filter_taps = 5;       ///< Taps per pass of the cross-bilateral filter (bilateral.h) run on V to smooth the
                             ///< jitter noise; odd, [1, 63]; 1 = no filter. Default 5: see docs/methods/cone.md, quality.

  /// Throws InputError naming the bad field.
  void validate() const;
  /// Copy with cones/spheres/prisms taken from the preset where they are unset.
  ConeParams resolved() const;
  VoxelizeOptions voxelize_options(float r_max) const;
};
/// Keys: preset ("low"|"medium"|"high"), cones, spheres, prisms, aperture_deg, depth_bits, columns,
/// grid ("world"|"eye"), weighting ("cosine"|"uniform"), open_meshes ("winding"|"slab"|"parity"), slab_fraction, jitter,
/// filter_taps.
void to_json(nlohmann::json& j, const ConeParams& p);
/// Rejects unknown keys, wrong types, unknown enum names and values out of range with InputError.
void from_json(const nlohmann::json& j, ConeParams& p);
/// The parameter table (core/params.h): JSON keys, ranges, defaults, help.
const ParamTable<ConeParams>& cone_param_table();

/// Table I: low (6 cones, 3 spheres, 3 prisms), medium (6, 5, 6), high (6, 7, 12); other fields default.
ConeParams cone_preset(ConeQuality q);

/// Derived constants of one parameter set: one pure function of the (resolved) parameters.
struct ConeSetup {
  struct Cone {
    float sin_theta, cos_theta, cos_phi, sin_phi;  ///< Unjittered axis in the normal's frame (theta from the normal).
    /// The cone's cell of the hemisphere, in which jitter places its axis: the band [band0, band1)
    /// of the measure's coordinate (sin^2 theta for cosine weighting, 1 - cos theta for uniform),
    /// where every value is equally likely, and the azimuth range [phi0, phi0 + dphi).
    float band0, band1, phi0, dphi;
  };
  struct Disk {
    float u, v, half_chord;  ///< Great-disk sample (unit radius) and sqrt(1 - u^2 - v^2).
  };
  std::vector<Cone> cones;
  std::vector<float> sphere_distance;  ///< d_k / R_max, k = 0 nearest the apex.
  std::vector<float> sphere_radius;    ///< r_k / R_max = d_k sin(alpha).
  std::vector<Disk> disk;              ///< Prism positions on the unit great disk.
  float sin_theta_max = 1;             ///< sin(90 deg - alpha): no axis lower, so cones stay above the tangent plane.
  float chain_ratio = 1;               ///< q = d_{k+1} / d_k = (1 + sin alpha) / (1 - sin alpha).
  bool cosine = true;                  ///< Bands in sin^2 theta (cosine weighting) or 1 - cos theta (uniform).
};
ConeSetup derive_cone_setup(const ConeParams& resolved);

/// The kernel: V for every covered pixel of `gbuffer` from `grid` (built from the same scene and,
/// for an eye grid, the same camera), with R_max = `r_max` world units. `params` must be resolved.
/// Pixel (x, y)'s rotations come from pixel_seed(seed, x, y): the result does not depend on the
/// thread count. Uncovered pixels get 1.
void compute_cone(const GBuffer& gbuffer, const VoxelGrid& grid, float r_max, const ConeParams& params, std::uint32_t seed,
                  ImageView<float> visibility, const ProgressFn& progress = {});

/// An open mesh of the scene and what analyze_closure took it for (voxelize.h, MeshKind).
struct OpenMeshInfo {
  std::string name;
  MeshKind kind = MeshKind::Sheet;
  std::size_t boundary_edges = 0;
  std::uint32_t holes = 0;
  float enclosure = 0;  ///< MeshClosure::enclosure.
};

struct ConeResult {
  Image<float> visibility;
  VoxelStats voxel_stats;  ///< Of the grid for the front of every object; winding_* summed over all grids.
  double voxelize_ms = 0;  ///< Every grid built in the call.
  double sides_ms = 0;     ///< Which side of the open meshes each pixel is on (open_meshes=winding).
  double trace_ms = 0, filter_ms = 0;
  int grid_nx = 0, grid_ny = 0;
  bool grid_reused = false;  ///< ConeContext: the grids of earlier calls were traced (no voxelization).
  /// Grids traced: one per combination of sides of the open meshes that the pixels lie on
  /// (voxelize.h: a sheet is a slab on the far side of it from the point), at most 8, each for at
  /// least 32 pixels (or a thousandth of the covered ones, if fewer).
  int side_grids = 1;
  std::size_t back_pixels = 0;        ///< Covered pixels traced with a grid for the back side of an open mesh.
  std::size_t rim_pixels = 0;         ///< Covered pixels traced with a grid for points beyond a sheet's free rim (no slab).
  std::size_t unresolved_pixels = 0;  ///< Pixels whose sides got no grid (a ninth, or one for too few pixels): traced with the all-front one.
  std::size_t side_evaluations = 0;   ///< Winding numbers evaluated per pixel to tell their sides.
  std::vector<OpenMeshInfo> open_meshes;  ///< The scene's meshes that are not closed.
  OpenMeshes open_mode = OpenMeshes::Winding;  ///< ConeParams::open_meshes of the call.
};

/// Voxelizes `scene` (rebuilt on every call: a dynamic-scene method), runs the kernel and the filter.
/// `closure` comes from analyze_closure(scene) (reusable across frames while the scene stays).
/// With open_meshes=winding each pixel is traced in the grid for the sides of the open meshes its
/// point lies on (voxelize.h; at most 8 grids per call, usually one or two; cone_stats reports
/// pixels left to the all-front grid).
ConeResult render_cone(const Scene& scene, std::span<const MeshClosure> closure, const GBuffer& gbuffer, float r_max, const ConeParams& params,
                       std::uint32_t seed, const ProgressFn& progress = {});

/// A scene prepared for cone tracing frame after frame: its mesh closure (analyze_closure) and the
/// last voxel grid with its coarse occupancy masks (voxelize.h), kept between calls. The paper
/// voxelizes every frame (a dynamic scene) and names building the grid once for static scenes as
/// future work (sec. V); this is that. The grid is rebuilt only when what it depends on changes:
///  - world grid: the voxelization options (columns, depth_bits, open_meshes, and the slab
///    thickness slab_fraction * R_max); the camera does not enter, so an orbiting view reuses it
///    (and the grids for the back sides of open meshes, kept per combination of sides);
///  - eye grid (the paper's): also the G-buffer, whose camera lays out the columns and whose depths
///    give z_nearest (eq. 2); it is reused only while the camera and the depths stay the same.
/// Every other parameter (cones, spheres, prisms, aperture, weighting, jitter, filter, seed) only
/// enters the trace. The output is bit-identical to render_cone's with the same arguments.
/// The scene is held by reference: it must outlive the context and not change while it is used
/// (for another scene, make another context).
class ConeContext {
 public:
  explicit ConeContext(const Scene& scene);
  /// As render_cone(scene, closure, gbuffer, r_max, params, seed, progress), voxelizing only when
  /// the grid's inputs changed (voxelize_ms is then the time of that; 0 with grid_reused).
  ConeResult render(const GBuffer& gbuffer, float r_max, const ConeParams& params, std::uint32_t seed, const ProgressFn& progress = {});
  /// How many grids have been built so far.
  int grid_builds() const { return builds_; }
  /// The scene it was made for.
  const Scene& scene() const { return scene_; }

 private:
  bool grid_is_current(const GBuffer& gbuffer, GridSpace space, const VoxelizeOptions& options) const;

  struct CachedGrid {
    VoxelGrid grid;
    VoxelStats stats;
  };
  const Scene& scene_;
  std::vector<MeshClosure> closure_;
  std::map<std::vector<std::uint32_t>, CachedGrid> grids_;  // per set of objects seen from their back (voxelize.h, `back`)
  std::shared_ptr<cone_internal::SideSetup> sides_;         // for sides_->r_max
  bool valid_ = false;  // grids_ were built from the members below
  int builds_ = 0;
  // What grids_ were built from.
  GridSpace space_ = GridSpace::World;
  VoxelizeOptions options_;
  Camera camera_;                     // eye grid only
  std::vector<float> depth_;          // eye grid only: the G-buffer's depth
  std::vector<std::uint8_t> coverage_;  // eye grid only
};

/// Numbers for --json: grid size, voxelization statistics, what each open mesh was taken for
/// ("open_mesh_kinds"), the grids per side, timings, and "warnings" (odd columns, sheets, solids
/// with holes, pixels beyond the grids of a frame), one line each, which the CLI prints.
nlohmann::json cone_stats(const ConeResult& result);

/// The method as the registry runs it (method.h): render_cone on in.scene with R_max =
/// in.falloff.radius (in.cache keeps a ConeContext between calls on the same Scene object), its
/// stats as cone_stats. InputError without a scene (a G-buffer file).
MethodOutput run(const MethodInput& in, const ConeParams& params);
/// InputError when `params` ask for what the GPU path lacks (the eye grid).
void check_gpu(const ConeParams& params);
/// The voxel grid's memory, for the check before a run.
MethodMemory memory(const ConeParams& params);

}  // namespace ao
