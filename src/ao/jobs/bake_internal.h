// SPDX-License-Identifier: Apache-2.0
// The pieces of the bake job (bake.h) shared by its files: the plan (the request with its defaults
// resolved and its inputs expanded), each mesh's output names, the occluders, and the bakers run
// as the plan says. Internal: not installed.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "ao/bake/texel_coverage.h"
#include "ao/io/mesh_io.h"
#include "ao/io/output_set.h"
#include "ao/jobs/bake.h"

namespace ao::bake_job {

namespace fs = std::filesystem;

/// A request with its defaults resolved and checked, and its inputs expanded.
struct Plan {
  BakeRequest r;               ///< raytraced.denoise, raytraced.bent_normals, histogram.bent_normals set.
  std::vector<fs::path> inputs;
  bool batch = false;          ///< Several meshes, or a folder: outputs named <stem>-<name>.
  int width = 1024, height = 1024;
  int png_bits = 8;

  /// A map is baked: unless only per-vertex AO is asked for.
  bool wants_map() const;
  /// The map file itself is written: when named, or under its default name when nothing else is asked for.
  bool writes_map_file() const;
  bool high_to_low() const { return !r.high.empty() || r.high_scene != nullptr; }
  /// Occluders, a floor, bake groups or high to low: the map is baked group by group.
  bool grouped() const;
};

/// Checks `request` and resolves its defaults (InputError naming the option).
Plan plan_bake(const BakeRequest& request);

/// The outputs of one mesh, each with what names it (for messages).
struct MeshOutputs {
  std::vector<std::pair<fs::path, std::string>> files;
  fs::path map, miss, bent, thickness, cavity, gltf, per_vertex;  ///< Empty when not written.
};
MeshOutputs outputs_of(const fs::path& input, const Plan& plan);

/// The transaction of one mesh's outputs: its inputs, then its outputs, checked now. `of_mesh`:
/// name the mesh in the option labels (a batch, where several meshes have a "-o").
void declare(OutputSet& set, const fs::path& input, const Plan& plan, const MeshOutputs& outs, bool of_mesh = false);

/// Bakes write per-vertex values and UV maps of each placed mesh, so glTF instances are loaded as
/// copies.
inline const LoadOptions kBakeLoad{.flatten_instances = true};

/// The --occluder meshes (UVs dropped: they occlude, they are not baked) and the floor under
/// `scene` (and `high`).
std::vector<Mesh> load_occluders(const Plan& plan, const Scene& scene, const Scene* high, const JobReporter& reporter);

/// The map of `scene`'s meshes with UVs by the plan's baker (the others occlude); ray-traced with
/// `rt` in place of the plan's settings when given (the AO family's maps).
BakeResult bake_map_plain(const Plan& plan, const Scene& scene, const TexelCoverage& coverage, const ProgressFn& progress,
                          const RaytracedBakeParams* rt = nullptr);
/// Per-vertex AO of every mesh of `scene`, concatenated; `rays` (may be null) gets the ray count.
std::vector<float> bake_vertices_of(const Plan& plan, const Scene& scene, std::uint64_t* rays, const ProgressFn& progress);

/// One mesh: loaded, baked, written (bake_mesh.cpp). Throws on failure.
MeshBake bake_mesh(const Plan& plan, const fs::path& input, const JobReporter& reporter);
/// A mesh the caller made (BakeRequest::scene): baked, not written.
MeshBake bake_scene(const Plan& plan, const Scene& scene, const JobReporter& reporter);

/// The provenance record of `input`'s outputs (bake_provenance), inputs hashed now.
nlohmann::json bake_record(const Plan& plan, const fs::path& input, bool hash_inputs = true);

/// A glTF input baked to a .glb keeps its document (bake_gltf.cpp).
bool is_gltf_round_trip(const fs::path& input, const Plan& plan);
MeshBake bake_gltf_input(const Plan& plan, const fs::path& input, const MeshOutputs& outs, OutputSet& outputs, const JobReporter& reporter);

/// The file's extension, lower case (".png").
std::string lower_extension(const fs::path& p);
/// Mean of `map` over its covered texels (1 when none).
double covered_mean(const BakeResult& map);

}  // namespace ao::bake_job
