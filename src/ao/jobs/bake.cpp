// SPDX-License-Identifier: Apache-2.0
// The bake job: the request checked and resolved before any mesh is loaded, each mesh's outputs
// named and declared, the bakers chosen, and the batch loop. One mesh is baked in bake_mesh.cpp,
// a glTF round trip in bake_gltf.cpp.
#include "ao/core/closest_name.h"
#include "ao/jobs/bake.h"

#include <algorithm>
#include <cctype>
#include <cstdio>

#include <tbb/global_control.h>

#include "ao/bake/bake_groups.h"
#include "ao/bake/denoise.h"
#include "ao/bake/per_vertex.h"
#include "ao/bake/udim.h"
#include "ao/core/error.h"
#include "ao/core/memory.h"
#include "ao/core/stopwatch.h"
#include "ao/io/image_io.h"
#include "ao/jobs/bake_internal.h"
#include "ao/jobs/fields.h"
#include "ao/jobs/provenance.h"
#include "ao/reference/ray_scene.h"

namespace ao {

std::string_view to_string(Baker baker) { return baker == Baker::Histogram ? "histogram" : "raytraced"; }

Baker baker_from_name(const std::string& name) {
  if (name == "raytraced") return Baker::Raytraced;
  if (name == "histogram") return Baker::Histogram;
  throw InputError(field(fields::kBakeMethod) + ": expected histogram or raytraced, got '" + name + "'" + did_you_mean(name, "histogram, raytraced"));
}

std::string_view to_string(BentNormalSpace space) { return space == BentNormalSpace::Tangent ? "tangent" : "world"; }

BentNormalSpace bent_normal_space_from_name(const std::string& name) {
  if (name == "world") return BentNormalSpace::World;
  if (name == "tangent") return BentNormalSpace::Tangent;
  throw InputError(field(fields::kBakeBentNormalSpace) + ": expected world or tangent, got '" + name + "'" + did_you_mean(name, "world, tangent"));
}

MapSize parse_map_size(const std::string& text) {
  auto side = [](const std::string& s) -> std::optional<int> {
    if (s.empty() || s.size() > 5 || !std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); })) return std::nullopt;
    const int v = std::stoi(s);
    if (v < 1 || v > kMaxMapSide) return std::nullopt;
    return v;
  };
  const std::size_t x = text.find_first_of("xX");
  const auto w = side(text.substr(0, x));
  const auto h = x == std::string::npos ? w : side(text.substr(x + 1));
  if (!w || !h)
    throw InputError(field(fields::kBakeSize) + ": expected N or WIDTHxHEIGHT (2048x1024), each in [1, " + std::to_string(kMaxMapSide) + "] texels, got '" + text + "'");
  return {*w, *h};
}

namespace bake_job {

namespace {

bool is_mesh_file(const fs::path& p) {
  const std::string e = lower_extension(p);
  return e == ".obj" || e == ".ply" || e == ".off" || e == ".stl" || e == ".gltf" || e == ".glb";
}

std::vector<fs::path> expand_inputs(const std::vector<fs::path>& inputs) {
  std::vector<fs::path> out;
  for (const fs::path& p : inputs) {
    if (!fs::is_directory(p)) {
      out.push_back(p);
      continue;
    }
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(p))
      if (e.is_regular_file() && is_mesh_file(e.path())) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    out.insert(out.end(), files.begin(), files.end());
  }
  return out;
}

// Output path for `given` (e.g. "ao.png") of input `in`: the path itself for one mesh; in a batch
// <out_dir or the input's folder>/<stem>-<name>, or <stem><fallback_suffix> when not given.
fs::path batch_path(const fs::path& in, const fs::path& given, const Plan& plan, const std::string& fallback_suffix) {
  if (!plan.batch && !given.empty()) return given;
  const fs::path dir = plan.r.out_dir.empty() ? in.parent_path() : plan.r.out_dir;
  if (given.empty()) return dir / (in.stem().string() + fallback_suffix);
  return dir / (in.stem().string() + "-" + given.filename().string());
}

// Bake groups, occluders and high to low: one way of forming groups; what each needs.
void check_grouping(const BakeRequest& r) {
  const int grouping = (r.match_by_name ? 1 : 0) + (r.groups.empty() ? 0 : 1) + (r.self_occlusion ? 1 : 0);
  if (grouping > 1) throw InputError(field(fields::kBakeMatchByName) + ", " + field(fields::kBakeGroups) + " and " + field(fields::kBakeSelfOcclusion) +
                                     ": give one way of forming bake groups");
  if (r.match_by_name && r.high.empty() && !r.high_scene) throw InputError(field(fields::kBakeMatchByName) + " needs " + field(fields::kBakeHigh) + ": it pairs low meshes NAME_low with high meshes NAME_high");
  if (grouping > 0 && !r.outputs.per_vertex.empty())
    throw InputError(field(fields::kBakePerVertex) + " with bake groups: per-vertex AO is baked with every mesh occluding; drop the grouping");
  if (r.floor && r.method == Baker::Histogram)
    throw InputError(field(fields::kBakeFloor) + " needs " + field(fields::kBakeMethod) + " raytraced: the histogram baker renders views covering the whole scene, and a floor 20 model diagonals "
                     "wide would make each view's pixels 400 times as many");
}

// High-to-low options: they need high meshes, the ray-traced baker, a texture map and one low mesh.
void check_high_to_low(const BakeRequest& r) {
  const HighToLowParams& h = r.high_to_low;
  const bool cage = !r.cage.empty() || r.cage_scene != nullptr;
  if (!r.high.empty() && r.high_scene) throw InputError(field(fields::kBakeHigh) + ": give high mesh files or a high scene made in memory, not both");
  if (!r.cage.empty() && r.cage_scene) throw InputError(field(fields::kBakeCage) + ": give a cage file or a cage made in memory, not both");
  if (r.high.empty() && !r.high_scene) {
    if (cage || h.cage_extrusion || h.max_front || h.max_back || !r.outputs.miss_mask.empty())
      throw InputError(field(fields::kBakeCage) + ", " + field(fields::kBakeCageExtrusion) + ", " + field(fields::kBakeMaxFront) + ", " + field(fields::kBakeMaxBack) +
                       " and " + field(fields::kBakeMissMask) + " need " + field(fields::kBakeHigh) + " (the high-poly mesh to bake from)");
    h.validate();  // every value in its range even where it is not used (--cage-points 0)
    return;
  }
  if (r.method == Baker::Histogram)
    throw InputError(
        field(fields::kBakeHigh) + " needs " + field(fields::kBakeMethod) +
        " raytraced: the histogram baker scatters each view's pixels into the texels of the surface it sees, "
        "and pixels of the high mesh have no texel in the low mesh's map without a cage ray per pixel, which is the ray-traced baker");
  if (!r.outputs.per_vertex.empty())
    throw InputError(field(fields::kBakePerVertex) + " with " + field(fields::kBakeHigh) + ": per-vertex AO is baked from the mesh itself; bake the high mesh's map, or drop " +
                     field(fields::kBakeHigh));
  if (cage && h.cage_extrusion)
    throw InputError(field(fields::kBakeCage) + " and " + field(fields::kBakeCageExtrusion) + ": give one (an explicit cage, or the low mesh pushed out by a distance)");
  if (!r.outputs.miss_mask.empty() && !is_supported_image_path(r.outputs.miss_mask))
    throw InputError(r.outputs.miss_mask.string() + ": unknown image extension (supported: " + supported_image_extensions() + ")" +
                     did_you_mean(r.outputs.miss_mask.extension().string(), supported_image_extensions()));
  h.validate();
}

// The settings of both bakers and the map's layout.
void check_settings(const BakeRequest& r) {
  if (r.raytraced.membership != Membership::Step && !r.raytraced.max_distance)
    throw InputError(field(fields::kBakeMembership) + " needs " + field(fields::kBakeMaxDistance) + ": with unlimited distance every occluder counts fully (there is no falloff)");
  if (r.raytraced.max_distance && r.raytraced.membership == Membership::Exp)
    throw InputError(field(fields::kBakeMembership) + ": use step, linear, sqrt or cubic for baking, got 'exp'");
  if (r.uv_set < 0 || r.uv_set > 7) throw InputError(field(fields::kBakeUvSet) + " must be in [0, 7] (UV sets count from 0), got " + std::to_string(r.uv_set));
  if (r.outputs.png_bits && *r.outputs.png_bits != 8 && *r.outputs.png_bits != 16) throw InputError(field(fields::kBakePngBits) + " must be 8 or 16, got " + std::to_string(*r.outputs.png_bits));
  if (r.padding < 0 || r.padding > 1024) throw InputError(field(fields::kBakePadding) + " must be in [0, 1024] texels, got " + std::to_string(r.padding));
  if (r.size && (r.size->width < 1 || r.size->height < 1 || r.size->width > kMaxMapSide || r.size->height > kMaxMapSide))
    throw InputError(field(fields::kBakeSize) + ": each side must be in [1, " + std::to_string(kMaxMapSide) + "] texels");
  VertexHistogramParams{.resolution = r.vertex_resolution}.validate();
}

// Output names are checked before any work, so a typo costs nothing and leaves nothing behind:
// known extensions, and (for a single mesh, whose outputs are the given paths) existing folders.
void check_output_names(const Plan& plan) {
  const BakeOutputs& o = plan.r.outputs;
  for (const fs::path& img : {o.map, o.bent_normals, o.thickness, o.cavity})
    if (!img.empty() && !is_supported_image_path(img))
      throw InputError(img.string() + ": unknown image extension (supported: " + supported_image_extensions() + ")" +
                       did_you_mean(img.extension().string(), supported_image_extensions()));
  if (!o.per_vertex.empty() && lower_extension(o.per_vertex) != ".ply" && lower_extension(o.per_vertex) != ".glb")
    throw InputError(o.per_vertex.string() + ": " + field(fields::kBakePerVertex) + " writes PLY or binary glTF (COLOR_0), give it a .ply or .glb name");
  if (!o.gltf.empty() && lower_extension(o.gltf) != ".glb") throw InputError(o.gltf.string() + ": " + field(fields::kBakeGltf) + " writes binary glTF, give it a .glb name");
  if (!plan.r.out_dir.empty()) {
    // Created when missing (asked for by name); an existing file of that name is an error.
    std::error_code ec;
    if (!fs::is_directory(plan.r.out_dir) && !fs::create_directories(plan.r.out_dir, ec))
      throw InputError(field(fields::kBakeOutDir) + ": cannot create folder " + plan.r.out_dir.string() +
                       (ec ? ": " + ec.message() : std::string(" (a file has that name)")));
  }
  if (plan.batch) return;  // outputs go to out_dir or beside each mesh
  for (const fs::path& out : {o.map, o.bent_normals, o.thickness, o.cavity, o.per_vertex, o.gltf}) {
    if (out.empty()) continue;
    const fs::path parent = out.parent_path();
    if (!parent.empty() && !fs::is_directory(parent)) throw InputError(out.string() + ": folder " + parent.string() + " does not exist");
  }
}

// --orm: one mesh, a PNG map output, a texture with red, green and blue; the map takes its size
// unless one is given (then they must agree) and its bit depth (so --png-bits does not apply).
void check_orm(Plan& plan) {
  const BakeRequest& r = plan.r;
  if (plan.batch) throw InputError(field(fields::kBakeOrm) + " packs the map of one mesh into one texture: give one mesh, not several or a folder");
  if (!plan.wants_map() || !plan.writes_map_file())
    throw InputError(field(fields::kBakeOrm) + " writes the map file: give " + field(fields::kBakeMap) + " a .png name (it is not written with only " +
                     field(fields::kBakeGltf) + ", " + field(fields::kBakeBentNormals) + " or " + field(fields::kBakePerVertex) + ")");
  if (!r.outputs.map.empty() && lower_extension(r.outputs.map) != ".png")
    throw InputError(r.outputs.map.string() + ": with " + field(fields::kBakeOrm) + " the map is the ORM texture with AO in red, a PNG; give " + field(fields::kBakeMap) + " a .png name");
  if (r.outputs.png_bits) throw InputError(field(fields::kBakePngBits) + " with " + field(fields::kBakeOrm) + ": the output keeps the ORM texture's own bit depth; drop " + field(fields::kBakePngBits));
  const StoredPng orm = read_stored_png(r.orm);
  if (orm.channels < 3)
    throw InputError(r.orm.string() + ": " + field(fields::kBakeOrm) + " needs an RGB or RGBA texture (occlusion, roughness, metalness in R, G, B); this one is greyscale");
  if (!r.size) {
    plan.width = orm.width;
    plan.height = orm.height;
  } else if (orm.width != plan.width || orm.height != plan.height) {
    const std::string orm_size = std::to_string(orm.width) + "x" + std::to_string(orm.height);
    throw InputError(r.orm.string() + ": the ORM texture is " + orm_size + " and the map " + field(fields::kBakeSize) + " " + std::to_string(plan.width) +
                     "x" + std::to_string(plan.height) + "; give " + field(fields::kBakeSize) + " " + orm_size + " or leave it unset");
  }
}

void check_udim(const Plan& plan) {
  const BakeRequest& r = plan.r;
  if (!is_udim_pattern(r.outputs.map)) return;
  const std::pair<bool, std::string> single_map_options[] = {{!r.outputs.gltf.empty(), field(fields::kBakeGltf) + " (a material takes one occlusion texture)"},
                                                            {!r.outputs.bent_normals.empty(), field(fields::kBakeBentNormals)},
                                                            {!r.outputs.thickness.empty(), field(fields::kBakeThickness)},
                                                            {!r.outputs.cavity.empty(), field(fields::kBakeCavity)},
                                                            {!r.outputs.miss_mask.empty(), field(fields::kBakeMissMask)},
                                                            {!r.orm.empty(), field(fields::kBakeOrm)},
                                                            {!r.reference.empty(), field(fields::kBakeReference)}};
  for (const auto& [given, what] : single_map_options)
    if (given)
      throw InputError(r.outputs.map.string() + ": UDIM tiles are written for the map only; " + what + " needs a single map, drop it or the tile pattern");
}

// The AO family's maps: ray-traced, with the AO map's settings but their own distance.
void check_family(const Plan& plan) {
  const BakeRequest& r = plan.r;
  const BakeOutputs& o = r.outputs;
  const std::pair<const fs::path*, std::string_view> family[] = {{&o.thickness, fields::kBakeThickness}, {&o.cavity, fields::kBakeCavity}};
  for (const auto& [path, name] : family)
    if (!path->empty() && r.method == Baker::Histogram)
      throw InputError(field(name) + " is baked by the ray-traced baker; drop " + field(fields::kBakeMethod) + " histogram");
  for (const auto& [value, name] : {std::pair{r.thickness_distance, fields::kBakeThicknessDistance}, std::pair{r.cavity_distance, fields::kBakeCavityDistance}})
    if (!(value > 0 && value <= 10))
      throw InputError(field(name) + " must be in (0, 10] (a fraction of the bounding-box diagonal), got " + float_text(value));
  if (!o.thickness.empty() && r.raytraced.ignore_back_faces)
    throw InputError(field(fields::kBakeThickness) + " looks into the mesh, where every hit is a back face; it cannot be baked with ignore_back_faces (the ray-traced setting)");
  if (r.bent_normal_space == BentNormalSpace::Tangent && o.bent_normals.empty())
    throw InputError(field(fields::kBakeBentNormalSpace) + " tangent is the space of " + field(fields::kBakeBentNormals) + "; name that output too");
}

// Both bakers' settings as the request sets them: the filter of ray-traced maps (high to low
// included: docs/methods/bake.md, "Denoising"), bent normals when their output is named.
void resolve_baker_settings(Plan& plan) {
  BakeRequest& r = plan.r;
  if (r.denoise && !plan.wants_map()) throw InputError(field(fields::kBakeDenoise) + " filters maps; per-vertex AO is not filtered, so drop " + field(fields::kBakeDenoise));
  r.raytraced.denoise = plan.wants_map() ? r.denoise.value_or(kDefaultBakeDenoise) : 0.0f;
  r.raytraced.bent_normals = r.histogram.bent_normals = !r.outputs.bent_normals.empty();
  r.raytraced.validate();  // before any mesh is loaded: samples, offset, denoise
  r.histogram.validate();
  if (r.raytraced.texel_sampling == TexelSampling::Centre) {
    if (r.method == Baker::Histogram) throw InputError(field(fields::kBakeTexelSampling) + " is the ray-traced baker's; the histogram baker samples each texel's patch");
    if (!r.outputs.per_vertex.empty()) throw InputError(field(fields::kBakeTexelSampling) + " centre is for maps: a vertex has no texel; bake per-vertex AO without it");
    if (plan.high_to_low()) throw InputError(field(fields::kBakeTexelSampling) + " centre is for single-mesh maps: high to low casts from each texel's patch of the cage");
  }
  check_family(plan);
}

void check_memory_of(const Plan& plan) {
  if (!plan.wants_map()) return;
  const int threads = static_cast<int>(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  const BakeRequest& r = plan.r;
  check_memory(estimate_bake_memory({.size = plan.width, .height = plan.height, .histogram = r.method == Baker::Histogram,
                                     .bent_normals = !r.outputs.bent_normals.empty(), .pixels_per_texel = r.histogram.pixels_per_texel,
                                     .threads = threads, .denoise = r.raytraced.denoise > 0}),
               "ao bake: a " + std::to_string(plan.width) + "x" + std::to_string(plan.height) + " map");
}

}  // namespace

bool Plan::wants_map() const { return r.outputs.per_vertex.empty() || !r.outputs.map.empty() || !r.outputs.gltf.empty(); }

bool Plan::writes_map_file() const {
  const BakeOutputs& o = r.outputs;
  return !o.map.empty() || (o.gltf.empty() && o.bent_normals.empty() && o.thickness.empty() && o.cavity.empty() && o.per_vertex.empty() &&
                            o.miss_mask.empty());
}

bool Plan::grouped() const { return high_to_low() || !r.occluders.empty() || r.floor || !r.groups.empty() || r.self_occlusion; }

Plan plan_bake(const BakeRequest& request) {
  Plan plan;
  plan.r = request;
  check_grouping(request);
  check_high_to_low(request);
  check_settings(request);
  resolve_baker_settings(plan);
  plan.width = request.size ? request.size->width : MapSize{}.width;
  plan.height = request.size ? request.size->height : MapSize{}.height;
  plan.png_bits = request.outputs.png_bits.value_or(8);
  if (!request.scene) {
    plan.inputs = expand_inputs(request.inputs);
    if (plan.inputs.empty()) throw InputError("no mesh files to bake (folders are searched for .obj .ply .off .stl .gltf .glb)");
    plan.batch = plan.inputs.size() > 1 || fs::is_directory(request.inputs.front());
  }
  if (plan.batch && plan.high_to_low())
    throw InputError(field(fields::kBakeHigh) + " bakes one low mesh: give one low-poly mesh file, not " + std::to_string(plan.inputs.size()) + " or a folder");
  check_output_names(plan);
  if (!request.orm.empty()) check_orm(plan);
  check_udim(plan);
  // Every output of the run is checked against every input and every other output before any
  // mesh is loaded (each mesh's outputs are then one transaction of their own).
  OutputSet all;
  for (const fs::path& in : plan.inputs) all.add_input(in, "the mesh " + in.string());
  for (const fs::path& in : plan.inputs) declare(all, in, plan, outputs_of(in, plan), plan.batch);
  check_memory_of(plan);
  return plan;
}

MeshOutputs outputs_of(const fs::path& input, const Plan& plan) {
  const BakeOutputs& o = plan.r.outputs;
  MeshOutputs out;
  if (plan.wants_map()) {
    out.map = batch_path(input, o.map, plan, "-ao.png");
    if (plan.writes_map_file()) out.files.emplace_back(out.map, o.map.empty() ? "the default map output" : field(fields::kBakeMap));
    if (!o.miss_mask.empty()) out.files.emplace_back(out.miss = batch_path(input, o.miss_mask, plan, "-miss.png"), field(fields::kBakeMissMask));
    if (!o.bent_normals.empty()) out.files.emplace_back(out.bent = batch_path(input, o.bent_normals, plan, "-bent.png"), field(fields::kBakeBentNormals));
    if (!o.thickness.empty()) out.files.emplace_back(out.thickness = batch_path(input, o.thickness, plan, "-thickness.png"), field(fields::kBakeThickness));
    if (!o.cavity.empty()) out.files.emplace_back(out.cavity = batch_path(input, o.cavity, plan, "-cavity.png"), field(fields::kBakeCavity));
    if (!o.gltf.empty()) out.files.emplace_back(out.gltf = batch_path(input, o.gltf, plan, "-ao.glb"), field(fields::kBakeGltf));
  }
  if (!o.per_vertex.empty()) out.files.emplace_back(out.per_vertex = batch_path(input, o.per_vertex, plan, "-ao.ply"), field(fields::kBakePerVertex));
  return out;
}

nlohmann::json bake_record(const Plan& plan, const fs::path& input, bool hash_inputs) {
  const BakeRequest& r = plan.r;
  std::vector<ProvenanceInput> inputs;
  if (!input.empty())
    for (const fs::path& f : files_read_by(input)) inputs.push_back({"mesh", f});
  for (const fs::path& f : r.high) inputs.push_back({"high", f});
  if (!r.cage.empty()) inputs.push_back({"cage", r.cage});
  for (const fs::path& f : r.occluders) inputs.push_back({"occluder", f});
  if (!r.orm.empty()) inputs.push_back({"orm", r.orm});
  if (!r.reference.empty()) inputs.push_back({"reference", r.reference});
  nlohmann::json s = {{"method", to_string(r.method)}, {"width", plan.width},   {"height", plan.height}, {"uv_set", r.uv_set},
                      {"padding", r.padding},          {"png_bits", plan.png_bits}, {"floor", r.floor},      {"groups", r.groups},
                      {"self_occlusion", r.self_occlusion}, {"match_by_name", r.match_by_name}};
  if (r.method == Baker::Histogram) {
    s["parameters"] = r.histogram;
    if (!r.outputs.per_vertex.empty()) s["vertex_resolution"] = r.vertex_resolution;
  } else {
    s["parameters"] = r.raytraced;  // its denoise and bent normals resolved by the plan
  }
  if (plan.high_to_low()) s["high_to_low"] = r.high_to_low;
  // Which outputs, by kind and format: a map written as EXR is not the PNG of the same bake.
  const BakeOutputs& o = r.outputs;
  const auto kind = [](const fs::path& p) { return p.empty() ? nlohmann::json() : nlohmann::json(lower_extension(p)); };
  s["outputs"] = {{"map", plan.wants_map() && plan.writes_map_file() ? kind(o.map.empty() ? fs::path("default.png") : o.map) : nlohmann::json()},
                  {"bent_normals", kind(o.bent_normals)}, {"per_vertex", kind(o.per_vertex)}, {"gltf", kind(o.gltf)}, {"miss_mask", kind(o.miss_mask)}};
  // The AO family's settings, only where asked for (the records of other bakes stay as they were).
  if (r.bent_normal_space == BentNormalSpace::Tangent) s["bent_normal_space"] = to_string(r.bent_normal_space);
  if (!o.thickness.empty()) s["outputs"]["thickness"] = kind(o.thickness), s["thickness_distance"] = r.thickness_distance;
  if (!o.cavity.empty()) s["outputs"]["cavity"] = kind(o.cavity), s["cavity_distance"] = r.cavity_distance;
  return provenance_record("bake", inputs, s, hash_inputs);
}

void declare(OutputSet& set, const fs::path& input, const Plan& plan, const MeshOutputs& outs, bool of_mesh) {
  const BakeRequest& r = plan.r;
  set.add_input(input, "the mesh " + input.string());
  set.add_input(r.reference, field(fields::kBakeReference));
  set.add_input(r.cage, field(fields::kBakeCage));
  set.add_input(r.orm, field(fields::kBakeOrm));
  for (const fs::path& f : r.high) set.add_input(f, field(fields::kBakeHigh));
  for (const fs::path& f : r.occluders) set.add_input(f, field(fields::kBakeOccluders));
  for (const auto& [path, what] : outs.files) set.add_output(path, of_mesh ? what + " of " + input.string() : what);
  if (plan.r.outputs.provenance)
    for (const auto& [path, what] : outs.files) set.add_output(provenance_path(path), field(fields::kBakeProvenance) + " of " + path.string());
}

std::vector<Mesh> load_occluders(const Plan& plan, const Scene& scene, const Scene* high, const JobReporter& reporter) {
  std::vector<Mesh> out;
  for (const fs::path& f : plan.r.occluders) {
    Scene s = load_scene_file(f, kBakeLoad);
    for (const std::string& w : s.warnings) reporter.warn(w);  // the loader names the file
    for (Mesh& m : s.meshes) {
      m.uvs.clear();
      out.push_back(std::move(m));
    }
  }
  if (plan.r.floor) {
    Bounds3 b = scene.bounds();
    if (high) b.extend(high->bounds());
    for (const Mesh& m : out) b.extend(m.bounds());
    out.push_back(make_floor_occluder(b));
  }
  return out;
}

BakeResult bake_map_plain(const Plan& plan, const Scene& scene, const TexelCoverage& coverage, const ProgressFn& progress, const RaytracedBakeParams* rt) {
  if (plan.r.method == Baker::Histogram) return bake_histogram(scene, coverage, plan.r.histogram, progress);
  const RayScene rays(scene, bake_bvh_options(scene.triangle_count()));
  return bake_raytraced(rays, coverage, rt ? *rt : plan.r.raytraced, progress);
}

std::vector<float> bake_vertices_of(const Plan& plan, const Scene& scene, std::uint64_t* rays, const ProgressFn& progress) {
  const BakeRequest& r = plan.r;
  if (r.method == Baker::Histogram)
    return bake_vertices_histogram(scene,
                                   {.directions = r.histogram.directions, .direction_set = r.histogram.direction_set,
                                    .resolution = r.vertex_resolution, .seed = r.histogram.seed},
                                   progress);
  const RayScene ray_scene(scene);
  return bake_vertices_raytraced(ray_scene, r.raytraced, rays, progress);
}

std::string lower_extension(const fs::path& p) {
  std::string e = p.extension().string();
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

double covered_mean(const BakeResult& map) {
  double sum = 0;
  for (std::size_t i = 0; i < map.mask.size(); ++i)
    if (map.mask[i]) sum += map.visibility[i];
  return map.covered_texels ? sum / static_cast<double>(map.covered_texels) : 1.0;
}

}  // namespace bake_job

BakeRequest resolve_bake_request(const BakeRequest& request) { return bake_job::plan_bake(request).r; }

nlohmann::json bake_provenance(const BakeRequest& request, const std::filesystem::path& mesh, bool hash_inputs) {
  const bake_job::Plan plan = bake_job::plan_bake(request);
  return bake_job::bake_record(plan, mesh, hash_inputs);
}

BakeBatchResult run_bake(const BakeRequest& request, const JobReporter& reporter, const std::function<void(const MeshBake&)>& on_mesh) {
  using namespace bake_job;
  const Plan plan = plan_bake(request);
  BakeBatchResult result;
  result.batch = plan.batch;
  if (request.scene) {
    result.meshes.push_back(bake_scene(plan, *request.scene, reporter));
  } else if (!plan.batch) {
    result.meshes.push_back(bake_mesh(plan, plan.inputs.front(), reporter));
  } else {
    for (std::size_t i = 0; i < plan.inputs.size(); ++i) {
      const fs::path& in = plan.inputs[i];
      const std::string head = "mesh " + std::to_string(i + 1) + " of " + std::to_string(plan.inputs.size()) + ": " + in.filename().string();
      reporter.trace(head + " ...");
      Stopwatch clock;
      MeshBake mesh;
      try {
        mesh = bake_mesh(plan, in, reporter);
      } catch (const std::runtime_error& e) {
        if (!dynamic_cast<const InputError*>(&e) && !dynamic_cast<const SystemError*>(&e)) throw;
        mesh.input = in;
        mesh.error = e.what();
        mesh.summary = {{"ao", build_info()}, {"input", in.string()}, {"error", mesh.error}};
        ++result.failed;
        const auto* input_error = dynamic_cast<const InputError*>(&e);
        reporter.fail(input_error ? input_error->marked() : mesh.error);  // the reporter names the fields its own way
      }
      char seconds[32];
      std::snprintf(seconds, sizeof seconds, "%.1f", clock.lap_ms() / 1000.0);
      reporter.trace(head + " ... " + (mesh.error.empty() ? "done" : "failed") + " in " + seconds + " s");
      if (on_mesh) on_mesh(mesh);
      result.meshes.push_back(std::move(mesh));
    }
  }
  if (!plan.batch && on_mesh) on_mesh(result.meshes.front());
  return result;
}

}  // namespace ao
