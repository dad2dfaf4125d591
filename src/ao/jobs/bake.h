// SPDX-License-Identifier: Apache-2.0
// `ao bake` as a library call: one mesh (or a batch of mesh files) with UVs in, its AO map,
// per-vertex AO, bent normals and a glTF with the map out, baked the way `ao bake` bakes by
// default (ray-traced, 64 rays per texel, texture-space denoising, padding). High to low, bake
// groups, occluders and a floor, UDIM tiles, ORM packing and glTF round trips are settings of the
// one request. The command line and the Python module bake through here.
//
//   BakeRequest r;
//   r.inputs = {"mesh.obj"};
//   r.outputs.map = "mesh-ao.png";
//   const BakeBatchResult out = run_bake(r);   // out.meshes[0].map.visibility: V per texel
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/bake/bake_result.h"
#include "ao/bake/high_to_low.h"
#include "ao/bake/histogram.h"
#include "ao/bake/padding.h"
#include "ao/bake/raytraced_bake.h"
#include "ao/jobs/reporter.h"
#include "ao/scene/mesh.h"

namespace ao {

/// The two texel bakers.
enum class Baker {
  Raytraced,  ///< Inside-out, Embree rays from each texel's patch (raytraced_bake.h): the default.
  Histogram,  ///< Outside-in, z-buffered views from many directions (McGraw & Sowers; histogram.h).
};
/// "raytraced", "histogram".
std::string_view to_string(Baker baker);
/// The baker called `name`; InputError naming --method and the choices otherwise.
Baker baker_from_name(const std::string& name);

/// The space bent normals are written in.
enum class BentNormalSpace {
  World,    ///< World-space direction.
  Tangent,  ///< The UV layout's tangent space, MikkTSpace frames (bake/tangents.h): what engines read.
};
/// "world", "tangent".
std::string_view to_string(BentNormalSpace space);
/// The space called `name`; InputError naming --bent-normals-space and the choices otherwise.
BentNormalSpace bent_normal_space_from_name(const std::string& name);

/// The size of a map, texels per side, each in [1, kMaxMapSide].
struct MapSize {
  int width = 1024, height = 1024;
};
inline constexpr int kMaxMapSide = 16384;
/// "1024" -> 1024 x 1024, "2048x1024" -> 2048 x 1024; InputError naming --size otherwise.
MapSize parse_map_size(const std::string& text);

/// The files a bake writes for a mesh; an empty path is not written. In a batch, each name is
/// used as <mesh stem>-<name> in the output folder (BakeRequest::out_dir, or beside each mesh).
struct BakeOutputs {
  /// The AO map: .png or .tif (8/16 bit), .tga (8 bit), .jpg (8 bit, lossy), .exr (float); linear.
  /// A name with <UDIM> or .1001. writes one map per UDIM tile. Without any output named, the map
  /// is written as <mesh stem>-ao.png.
  std::filesystem::path map;
  std::filesystem::path bent_normals;  ///< The average open direction, n * 0.5 + 0.5, in BakeRequest::bent_normal_space.
  /// The thickness map (ray-traced): the inside hemisphere's mean of min(d / R, 1) (linear
  /// membership), R = BakeRequest::thickness_distance: 1 where the mesh reaches R or more behind
  /// the surface, darker the thinner it is. Same formats as the map.
  std::filesystem::path thickness;
  /// The cavity map (ray-traced): AO as the map bakes it, with R = BakeRequest::cavity_distance:
  /// only the small creases darken. Same formats as the map.
  std::filesystem::path cavity;
  std::filesystem::path per_vertex;    ///< Per-vertex AO: .ply (colour + float quality) or .glb (COLOR_0).
  std::filesystem::path gltf;          ///< A .glb of the mesh with the map as its occlusion texture.
  std::filesystem::path miss_mask;     ///< High to low: 1 where every cage ray of a texel missed.
  std::optional<int> png_bits;         ///< 8 or 16 (default 8; an ORM texture keeps its own).
  /// Also write each output's record beside it, <output>.ao.json (jobs/provenance.h): ao's version,
  /// the inputs' SHA-256, every setting; in the mesh's transaction, renamed after its outputs.
  bool provenance = false;
};

struct BakeRequest {
  /// Mesh files (OBJ, PLY, OFF, STL, glTF/GLB) or folders of them; several, or a folder, make a
  /// batch in which each mesh is baked in turn and a failure does not stop the others.
  std::vector<std::filesystem::path> inputs;
  /// A mesh the caller made, baked instead of `inputs` (no glTF round trip). Validated.
  std::shared_ptr<const Scene> scene;
  Baker method = Baker::Raytraced;  ///< Raytraced: the better error per second (docs/methods/bake.md, "Defaults").
  std::optional<MapSize> size;      ///< Default 1024 x 1024; with an ORM texture, its size.
  int uv_set = 0;                   ///< Which UV set to bake into, [0, 7] (glTF TEXCOORD_n).
  int padding = kDefaultPadding;    ///< Texels filled outside the charts from the nearest chart texel, [0, 1024].
  /// The ray-traced baker's settings (its seed keys the sample sets). bent_normals and denoise are
  /// set by the job from `outputs` and `denoise`.
  RaytracedBakeParams raytraced;
  /// Sigma, texels, of the texture-space filter of ray-traced maps, [0, kMaxDenoiseSigma]; 0 = off.
  /// Unset: kDefaultBakeDenoise (docs/methods/bake.md, "Denoising"). Per-vertex AO is never filtered.
  std::optional<float> denoise;
  BentNormalSpace bent_normal_space = BentNormalSpace::World;
  /// R of the thickness map as a fraction of the baked meshes' bounding-box diagonal, (0, 10].
  /// 0.25: the thin parts of a figure (ears, fingers, cloth) grade from dark to white.
  float thickness_distance = 0.25f;
  /// R of the cavity map as a fraction of the baked meshes' bounding-box diagonal, (0, 10].
  /// 0.02: creases a few hundredths of the model's size across.
  float cavity_distance = 0.02f;
  HistogramParams histogram;        ///< The histogram baker's settings; bent_normals set by the job.
  int vertex_resolution = 1024;     ///< Histogram per-vertex bakes: view size in pixels, [64, 8192].
  // High to low: the AO of the high meshes baked into the low mesh's UVs (ray-traced).
  std::vector<std::filesystem::path> high;
  std::filesystem::path cage;       ///< An explicit cage mesh (the low mesh's topology, pushed out).
  /// High meshes the caller made (one scene, validated), baked from instead of `high` files: a
  /// program's meshes in memory (Blender's objects through the Python module). Not with `high`.
  std::shared_ptr<const Scene> high_scene;
  /// An explicit cage the caller made (validated; the low mesh's topology), instead of `cage`.
  std::shared_ptr<const Scene> cage_scene;
  HighToLowParams high_to_low;      ///< Cage extrusion and ray reach; its `ao` comes from `raytraced`.
  // Occluders and bake groups.
  std::vector<std::filesystem::path> occluders;  ///< Meshes that occlude but are not baked.
  bool floor = false;               ///< A ground plane under the model (y up) as an occluder.
  std::vector<std::vector<std::string>> groups;  ///< Mesh names that occlude each other and nothing else.
  bool self_occlusion = false;      ///< Each mesh occluded only by itself (and the occluders).
  bool match_by_name = false;       ///< With high: NAME_low bakes only from NAME_high (Substance's convention).
  std::filesystem::path orm;        ///< Write the map into the red channel of this ORM texture (PNG).
  std::filesystem::path reference;  ///< Compare the map with this reference map over covered texels.
  BakeOutputs outputs;
  std::filesystem::path out_dir;    ///< Folder of a batch's outputs (default: beside each mesh); created when missing.
};

/// The outcome of one mesh.
struct MeshBake {
  std::filesystem::path input;
  BakeResult map;                  ///< Padded; empty when no map was asked for (or a UDIM or glTF round trip wrote several).
  Image<float> thickness, cavity;  ///< Padded; empty unless asked for (BakeOutputs).
  std::vector<float> vertex_ao;    ///< Per vertex of each mesh, concatenated; empty unless asked for.
  std::string error;               ///< In a batch: the one-line error of a mesh that failed; empty on success.
  nlohmann::json summary;          ///< What `ao bake --json` prints for it.
};

/// What run_bake returns. Keep it in a variable, or take what you need with mesh(): a reference
/// into a temporary result, such as `const BakeResult& map = run_bake(r).meshes.at(0).map;`,
/// dangles at the end of the statement (the vector is freed with the result).
struct BakeBatchResult {
  std::vector<MeshBake> meshes;  ///< In input order (folders sorted by name).
  int failed = 0;                ///< Meshes with an error.
  bool batch = false;            ///< Several meshes or a folder were asked for (outputs named <stem>-<name>).

  /// The first mesh's outcome (the only one of a single mesh). On a result held in a variable, a
  /// reference into it; on a temporary, the outcome moved out of it, so that
  /// `const MeshBake& m = run_bake(r).mesh();` and `const BakeResult& map = run_bake(r).mesh().map;`
  /// keep it alive (a reference bound to a temporary, or to a member of one, extends its life).
  /// std::out_of_range when there is none.
  const MeshBake& mesh() const& { return meshes.at(0); }
  MeshBake mesh() && { return std::move(meshes.at(0)); }
};

/// The checks that need no mesh (option values, combinations, output names, memory), with the
/// defaults resolved: what run_bake bakes. InputError with one line naming the option.
BakeRequest resolve_bake_request(const BakeRequest& request);

/// The provenance record (jobs/provenance.h) of the outputs `request` writes for `mesh`, without
/// the per-file "output": the mesh (and a .gltf's buffers), high meshes, cage, occluders, ORM
/// texture and reference map as inputs (hashed when `hash_inputs`; otherwise each input has its
/// role and path only), and as settings every resolved field that changes an output (the baker
/// and its parameters, size, UV set, padding, denoise, high-to-low reach, groups, floor, PNG bits,
/// which outputs). Checks the request first (resolve_bake_request).
nlohmann::json bake_provenance(const BakeRequest& request, const std::filesystem::path& mesh, bool hash_inputs = true);

/// Bakes every mesh of `request` and writes its outputs, each mesh's as one transaction. In a
/// batch a mesh that fails (InputError, SystemError) is reported through `reporter` and in its
/// MeshBake, and the rest are still baked; a single mesh's error is thrown. `on_mesh` (optional)
/// is called after each mesh.
BakeBatchResult run_bake(const BakeRequest& request, const JobReporter& reporter = {},
                         const std::function<void(const MeshBake&)>& on_mesh = {});

}  // namespace ao
