// ao bake: mesh(es) with UVs -> AO map (PNG/EXR), optionally per-vertex AO (PLY) and a .glb with
// the map as the occlusion texture. Several meshes or a folder are baked in turn; a failure is
// reported and the rest are still baked (exit status 1 if any failed).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <utility>

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>
#include <unistd.h>

#include "ao/bake/bake_groups.h"
#include "ao/bake/denoise.h"
#include "ao/bake/high_to_low.h"
#include "ao/bake/histogram.h"
#include "ao/bake/padding.h"
#include "ao/bake/per_vertex.h"
#include "ao/bake/raytraced_bake.h"
#include "ao/bake/udim.h"
#include "ao/core/error.h"
#include "ao/core/memory.h"
#include "ao/eval/metrics.h"
#include "ao/io/atomic_file.h"
#include "ao/io/gltf_export.h"
#include "ao/io/image_io.h"
#include "ao/io/mesh_io.h"
#include "ao/io/output_set.h"
#include "ao/io/ply_export.h"
#include "ao/reference/ray_scene.h"
#include "bake_gltf.h"
#include "common.h"
#include "subcommands.h"

namespace ao::cli {

namespace {

namespace fs = std::filesystem;

struct BakeOptions {
  std::vector<std::string> inputs;
  std::string output, out_dir, per_vertex, gltf, bent, reference;
  // The default by measured quality per second: on refined_elephant_uv at 1024^2, raytraced at 64 rays
  // per texel is within RMSE 0.02 of a 1024-ray bake in less time than any histogram setting
  // reaches 0.035 (docs/methods/bake.md, "Defaults").
  std::string method = "raytraced";
  bool method_given = false;  // -m was on the command line (high-to-low then picks raytraced itself)
  // Options given on the command line that only one baker reads, by name ("--directions", ...).
  std::vector<std::string> histogram_only, raytraced_only;
  // High to low (high_to_low.h).
  std::vector<std::string> high;
  std::string cage, miss_mask;
  HighToLowParams h2l;
  // Occluders and bake groups (bake_groups.h).
  std::vector<std::string> occluders, groups;
  bool floor = false, match_by_name = false, self_occlusion = false;
  std::string size_text = "1024";  // -s: N (square) or WxH
  int width = 1024, height = 1024;  // from size_text
  bool size_given = false, png_bits_given = false;
  std::string orm;  // --orm: the ORM texture whose red channel the map replaces
  int uv_set = 0;
  int padding = kDefaultPadding;
  int png_bits = 8;
  bool json = false;
  HistogramParams hist;
  std::string direction_set = "fibonacci", normalization = "area";
  std::string normal = "shading";  // --normal, parsed into rt.normal
  RaytracedBakeParams rt;
  float denoise = kDefaultBakeDenoise;  // --denoise, into rt.denoise for maps of the ray-traced baker
  bool denoise_given = false;
  std::optional<float> max_distance;
  std::string membership = "step";
  int vertex_resolution = 1024;
  std::uint32_t seed = 1;
};

bool is_mesh_file(const fs::path& p) {
  std::string e = p.extension().string();
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e == ".obj" || e == ".ply" || e == ".off" || e == ".stl" || e == ".gltf" || e == ".glb";
}

std::vector<fs::path> expand_inputs(const std::vector<std::string>& inputs) {
  std::vector<fs::path> out;
  for (const std::string& in : inputs) {
    const fs::path p(in);
    if (fs::is_directory(p)) {
      std::vector<fs::path> files;
      for (const auto& e : fs::directory_iterator(p))
        if (e.is_regular_file() && is_mesh_file(e.path())) files.push_back(e.path());
      std::sort(files.begin(), files.end());
      out.insert(out.end(), files.begin(), files.end());
    } else {
      out.push_back(p);
    }
  }
  return out;
}

std::string read_bytes(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

// Output path for `name` (e.g. "ao.png") of input `in` in a batch: <out_dir or input's folder>/<stem>-<name>.
fs::path batch_path(const fs::path& in, const std::string& given, const std::string& out_dir, bool batch, const std::string& fallback_suffix) {
  if (!batch && !given.empty()) return given;
  const fs::path dir = out_dir.empty() ? in.parent_path() : fs::path(out_dir);
  if (given.empty()) return dir / (in.stem().string() + fallback_suffix);
  return dir / (in.stem().string() + "-" + fs::path(given).filename().string());
}

// "1024" -> 1024 x 1024, "2048x1024" -> 2048 x 1024; nullopt unless each side is a whole number in [1, 16384].
std::optional<std::pair<int, int>> parse_map_size(const std::string& text) {
  auto side = [](const std::string& s) -> std::optional<int> {
    if (s.empty() || s.size() > 5 || !std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); })) return std::nullopt;
    const int v = std::stoi(s);
    if (v < 1 || v > 16384) return std::nullopt;
    return v;
  };
  const std::size_t x = text.find_first_of("xX");
  const auto w = side(text.substr(0, x));
  const auto h = x == std::string::npos ? w : side(text.substr(x + 1));
  if (!w || !h) return std::nullopt;
  return std::pair{*w, *h};
}

std::string lower_extension(const fs::path& p) {
  std::string e = p.extension().string();
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

// Output names are checked before any work, so a typo costs nothing and leaves nothing behind:
// known extensions, and (for a single mesh, whose outputs are the given paths) existing folders.
void check_output_names(const BakeOptions& o, bool batch) {
  for (const std::string& img : {o.output, o.bent})
    if (!img.empty() && !is_supported_image_path(img))
      throw InputError(img + ": unknown image extension (supported: " + supported_image_extensions() + ")");
  if (!o.per_vertex.empty() && lower_extension(o.per_vertex) != ".ply" && lower_extension(o.per_vertex) != ".glb")
    throw InputError(o.per_vertex + ": --per-vertex writes PLY or binary glTF (COLOR_0), give it a .ply or .glb name");
  if (!o.gltf.empty() && lower_extension(o.gltf) != ".glb") throw InputError(o.gltf + ": --gltf writes binary glTF, give it a .glb name");
  if (!o.out_dir.empty()) {
    // Created when missing (asked for by name); an existing file of that name is an error.
    std::error_code ec;
    if (!fs::is_directory(o.out_dir) && !fs::create_directories(o.out_dir, ec))
      throw InputError("--out-dir: cannot create folder " + o.out_dir + (ec ? ": " + ec.message() : std::string(" (a file has that name)")));
  }
  if (batch) return;  // outputs go to --out-dir or beside each mesh
  for (const std::string& out : {o.output, o.bent, o.per_vertex, o.gltf}) {
    if (out.empty()) continue;
    const fs::path parent = fs::path(out).parent_path();
    if (!parent.empty() && !fs::is_directory(parent)) throw InputError(out + ": folder " + parent.string() + " does not exist");
  }
}

// The outputs of one mesh, each with the option that names it (for messages).
struct MeshOutputs {
  std::vector<std::pair<fs::path, std::string>> files;
  fs::path map, miss, bent, gltf, per_vertex;  ///< Empty when not written.
};

bool wants_map(const BakeOptions& o) { return o.per_vertex.empty() || !o.output.empty() || !o.gltf.empty(); }
// The map file itself: when -o names it, or under its default name when nothing else is asked for.
bool writes_map_file(const BakeOptions& o) {
  return !o.output.empty() || (o.gltf.empty() && o.bent.empty() && o.per_vertex.empty() && o.miss_mask.empty());
}

MeshOutputs outputs_of(const fs::path& input, const BakeOptions& o, bool batch) {
  MeshOutputs out;
  if (wants_map(o)) {
    out.map = batch_path(input, o.output, o.out_dir, batch, "-ao.png");
    if (writes_map_file(o)) out.files.emplace_back(out.map, o.output.empty() ? "the default map output" : "-o");
    if (!o.miss_mask.empty()) {
      out.miss = batch_path(input, o.miss_mask, o.out_dir, batch, "-miss.png");
      out.files.emplace_back(out.miss, "--miss-mask");
    }
    if (!o.bent.empty()) {
      out.bent = batch_path(input, o.bent, o.out_dir, batch, "-bent.png");
      out.files.emplace_back(out.bent, "--bent-normals");
    }
    if (!o.gltf.empty()) {
      out.gltf = batch_path(input, o.gltf, o.out_dir, batch, "-ao.glb");
      out.files.emplace_back(out.gltf, "--gltf");
    }
  }
  if (!o.per_vertex.empty()) {
    out.per_vertex = batch_path(input, o.per_vertex, o.out_dir, batch, "-ao.ply");
    out.files.emplace_back(out.per_vertex, "--per-vertex");
  }
  return out;
}

// The transaction of one mesh's outputs (output_set.h): its inputs, then its outputs, checked now.
// `of_mesh`: name the mesh in the option labels (a batch, where several meshes have a "-o").
void declare(OutputSet& set, const fs::path& input, const BakeOptions& o, const MeshOutputs& outs, bool of_mesh = false) {
  set.add_input(input, "the mesh " + input.string());
  set.add_input(o.reference, "--reference");
  set.add_input(o.cage, "--cage");
  set.add_input(o.orm, "--orm");
  for (const std::string& f : o.high) set.add_input(f, "--high");
  for (const std::string& f : o.occluders) set.add_input(f, "--occluder");
  for (const auto& [path, what] : outs.files) set.add_output(path, of_mesh ? what + " of " + input.string() : what);
}

// Bakes write per-vertex values and UV maps of each placed mesh, so glTF instances are loaded as
// copies (LoadOptions::flatten_instances).
constexpr LoadOptions kBakeLoad{.flatten_instances = true};

// The high meshes of --high, one scene (their UVs are not used).
Scene load_high_scene(const std::vector<std::string>& files) {
  Scene high;
  high.name = files.size() == 1 ? files.front() : "--high meshes";
  for (const std::string& f : files) {
    Scene s = load_scene_file(f, kBakeLoad);
    for (const std::string& w : s.warnings) std::cerr << "warning: " << f << ": " << w << "\n";
    for (Mesh& m : s.meshes) high.meshes.push_back(std::move(m));
  }
  return high;
}

// --occluder meshes (UVs dropped: they occlude, they are not baked) and the --floor.
std::vector<Mesh> load_occluders(const BakeOptions& o, const Scene& scene, const Scene* high) {
  std::vector<Mesh> out;
  for (const std::string& f : o.occluders) {
    Scene s = load_scene_file(f, kBakeLoad);
    for (const std::string& w : s.warnings) std::cerr << "warning: " << f << ": " << w << "\n";
    for (Mesh& m : s.meshes) {
      m.uvs.clear();
      out.push_back(std::move(m));
    }
  }
  if (o.floor) {
    Bounds3 b = scene.bounds();
    if (high) b.extend(high->bounds());
    for (const Mesh& m : out) b.extend(m.bounds());
    out.push_back(make_floor_occluder(b));
  }
  return out;
}

// Bake groups: by name, explicit lists, one per mesh, or everything in one.
std::vector<BakeGroup> make_groups(const BakeOptions& o, const Scene& scene, const Scene* high) {
  std::vector<BakeGroup> groups;
  if (o.match_by_name) {
    std::vector<std::string> unused;
    groups = groups_by_name(scene, *high, &unused);
    for (const std::string& n : unused) std::cerr << "warning: --match-by-name: high mesh '" << n << "' matches no low mesh and is not used\n";
    return groups;
  }
  if (!o.groups.empty()) {
    std::vector<std::vector<std::string>> lists;
    for (const std::string& g : o.groups) {
      std::vector<std::string>& l = lists.emplace_back();
      std::stringstream ss(g);
      for (std::string name; std::getline(ss, name, ',');)
        if (!name.empty()) l.push_back(name);
    }
    groups = groups_from_lists(scene, lists);
  } else if (o.self_occlusion) {
    groups = groups_per_mesh(scene);
  } else {
    BakeGroup all{"", {}, {}};
    for (std::size_t i = 0; i < scene.meshes.size(); ++i) all.meshes.push_back(i);
    groups.push_back(std::move(all));
  }
  if (high)
    for (BakeGroup& g : groups)
      for (std::size_t i = 0; i < high->meshes.size(); ++i) g.high.push_back(i);
  return groups;
}

// The map baked group by group: high to low (AO at the group's high meshes, occluded by them and
// the occluders), or the group's own meshes with the occluders.
BakeResult bake_in_groups(const fs::path& input, const Scene& scene, const Scene* high, const std::vector<Mesh>& occluders, const BakeOptions& o,
                          const RaytracedBakeParams& rt, const HistogramParams& hist, nlohmann::json& summary, const ProgressFn& progress) {
  const std::vector<BakeGroup> groups = make_groups(o, scene, high);
  std::optional<CagePositions> cage;  // of the whole low scene; each group takes its meshes' cages
  HighToLowParams p = o.h2l;
  p.ao = rt;
  if (high) {
    if (!o.cage.empty()) {
      cage = cage_from_mesh(scene, load_scene_file(o.cage, kBakeLoad));
    } else {
      if (!p.cage_extrusion) p.cage_extrusion = kDefaultCageFraction * scene.bounds().diagonal();
      cage = extrude_cage(scene, *p.cage_extrusion);
    }
  }
  BakeResult r = bake_groups(scene, groups, high ? std::vector<Mesh>{} : occluders, o.width, o.height,
                             [&](const Scene& gs, const TexelCoverage& cov, const BakeGroup& g) -> BakeResult {
                               if (!high) {
                                 if (o.method == "histogram") return bake_histogram(gs, cov, hist, progress);
                                 const RayScene rays(gs, bake_bvh_options(gs.triangle_count()));
                                 return bake_raytraced(rays, cov, rt, progress);
                               }
                               Scene targets;
                               targets.name = high->name;
                               for (std::size_t i : g.high) targets.meshes.push_back(high->meshes[i]);
                               Scene blockers = targets;
                               for (const Mesh& m : occluders) blockers.meshes.push_back(m);
                               CagePositions gc;
                               for (std::size_t i : g.meshes) gc.push_back((*cage)[i]);
                               const RayScene target_rays(targets, high_to_low_target_bvh_options(targets.triangle_count()));
                               const RayScene blocker_rays(blockers, bake_bvh_options(blockers.triangle_count()));
                               return bake_high_to_low(gs, cov, gc, target_rays, blocker_rays, p, progress);
                             });
  if (groups.size() > 1) summary["groups"] = groups.size();
  if (!occluders.empty()) summary["occluder_meshes"] = occluders.size();
  if (high) {
    summary["high"] = o.high;
    summary["high_triangles"] = high->triangle_count();
    summary["missed_texels"] = r.missed_texels;
    summary["parameters"] = p;
    if (r.missed_texels > 0)
      std::cerr << "warning: " << input.string() << ": " << r.missed_texels << " of " << r.covered_texels
                << " texels: every cage ray missed the high mesh; filled from their neighbours (raise --cage-extrusion or --max-back"
                << (o.miss_mask.empty() ? "; --miss-mask shows where)" : ")") << "\n";
  }
  return r;
}

// A glTF input baked to --gltf or --per-vertex .glb: the document's round trip (bake_gltf.h).
bool is_gltf_round_trip(const fs::path& input, const BakeOptions& o) {
  return (!o.gltf.empty() || lower_extension(o.per_vertex) == ".glb") && is_gltf_file(input);
}

// Both bakers' parameters as the options set them (seed, distance, membership).
std::pair<RaytracedBakeParams, HistogramParams> baker_params(const BakeOptions& o) {
  RaytracedBakeParams rt = o.rt;
  rt.seed = o.seed;
  rt.max_distance = o.max_distance;
  if (o.max_distance) rt.membership = *parse_membership(o.membership);  // checked by run_bake
  HistogramParams hist = o.hist;
  hist.seed = o.seed;
  return {rt, hist};
}

nlohmann::json bake_gltf_input(const fs::path& input, const BakeOptions& o, const MeshOutputs& outs, OutputSet& outputs, const GlobalOptions& global) {
  const std::pair<bool, const char*> unsupported[] = {{!o.high.empty(), "--high"},
                                                      {!o.groups.empty() || o.self_occlusion || o.match_by_name, "bake groups"},
                                                      {!o.bent.empty(), "--bent-normals"},
                                                      {!o.orm.empty(), "--orm"},
                                                      {!o.reference.empty(), "--reference"},
                                                      {!o.per_vertex.empty() && lower_extension(o.per_vertex) != ".glb", "--per-vertex .ply"},
                                                      {is_udim_pattern(o.output), "UDIM tiles"}};
  for (const auto& [given, what] : unsupported)
    if (given)
      throw InputError(input.string() + ": a glTF input baked to a .glb keeps its document, one map per glTF mesh; " + what +
                       " does not apply to it (bake without --gltf/--per-vertex .glb for the flattened scene)");
  const bool progress = !global.quiet && stderr_is_terminal();
  const std::pair<RaytracedBakeParams, HistogramParams> params = baker_params(o);
  const RaytracedBakeParams& rt = params.first;
  const HistogramParams& hist = params.second;
  GltfRoundTrip job;
  job.input = input;
  job.gltf = outs.gltf;
  job.per_vertex = outs.per_vertex;
  if (writes_map_file(o) && !o.output.empty()) job.map = outs.map;
  job.uv_set = o.uv_set;
  job.width = o.width;
  job.height = o.height;
  job.png_bits = o.png_bits;
  job.padding = o.padding;
  job.json = o.json;
  job.occluders = [&](const Scene& world) { return load_occluders(o, world, nullptr); };
  job.bake_map = [&](const Scene& scene, const std::string& label) {
    const TexelCoverage cov = compute_texel_coverage(scene, o.width, o.height);
    for (const std::string& w : cov.warnings()) std::cerr << "warning: " << input.string() << ": mesh " << label << ": " << w << "\n";
    ProgressBar bar("bake " + input.filename().string() + " " + label, progress);
    if (o.method == "histogram") return bake_histogram(scene, cov, hist, bar.callback());
    const RayScene rays(scene, bake_bvh_options(scene.triangle_count()));
    return bake_raytraced(rays, cov, rt, bar.callback());
  };
  job.bake_vertices = [&](const Scene& scene, std::uint64_t* nrays) {
    ProgressBar bar("per-vertex " + input.filename().string(), progress);
    if (o.method == "histogram")
      return bake_vertices_histogram(scene, {.directions = hist.directions, .direction_set = hist.direction_set, .resolution = o.vertex_resolution, .seed = o.seed},
                                     bar.callback());
    const RayScene rays(scene);
    return bake_vertices_raytraced(rays, rt, nrays, bar.callback());
  };
  nlohmann::json summary = bake_gltf_round_trip(job, outputs);
  summary["method"] = o.method;
  outputs.commit();
  return summary;
}

nlohmann::json bake_one(const fs::path& input, const BakeOptions& o, bool batch, const GlobalOptions& global) {
  Stopwatch clock;
  nlohmann::json timings;
  const bool progress = !global.quiet && stderr_is_terminal();
  const MeshOutputs outs = outputs_of(input, o, batch);
  OutputSet outputs;
  declare(outputs, input, o, outs);
  if (is_gltf_round_trip(input, o)) return bake_gltf_input(input, o, outs, outputs, global);
  Scene scene = load_scene_file(input, {.uv_set = o.uv_set, .flatten_instances = true});
  for (const std::string& w : scene.warnings) std::cerr << "warning: " << input.string() << ": " << w << "\n";
  timings["load_ms"] = clock.lap_ms();
  nlohmann::json summary = {{"input", input.string()}, {"method", o.method}, {"triangles", scene.triangle_count()}, {"vertices", scene.vertex_count()}};
  const std::pair<RaytracedBakeParams, HistogramParams> params = baker_params(o);
  const RaytracedBakeParams& rt = params.first;
  const HistogramParams& hist = params.second;
  std::unique_ptr<RayScene> rays;
  auto ray_scene = [&]() -> RayScene& {
    if (!rays) {
      check_memory(estimate_ray_scene_memory(scene.triangle_count(), scene.vertex_count()),
                   input.string() + ": the BVH of " + std::to_string(scene.triangle_count()) + " triangles");
      rays = std::make_unique<RayScene>(scene, bake_bvh_options(scene.triangle_count()));
      timings["bvh_ms"] = clock.lap_ms();
    }
    return *rays;
  };

  std::optional<Scene> high;
  if (!o.high.empty()) high = load_high_scene(o.high);
  const std::vector<Mesh> occluders = load_occluders(o, scene, high ? &*high : nullptr);
  const bool grouped = high || !occluders.empty() || !o.groups.empty() || o.self_occlusion;
  const bool want_map = wants_map(o);
  const bool has_uv = std::any_of(scene.meshes.begin(), scene.meshes.end(), [](const Mesh& m) { return !m.uvs.empty(); });
  if (want_map && !has_uv)
    throw InputError(input.string() + ": the mesh has no UV coordinates, so it cannot be baked to a texture; use --per-vertex out.ply for per-vertex AO");

  // Everything is computed first and written at the end, so a mesh that fails half-way (or a
  // per-vertex bake that fails after the map) leaves no partial set of outputs behind.
  BakeResult r;
  double bake_ms = 0;
  fs::path map_out;
  // UDIM: -o names a pattern (<UDIM> or .1001.); each tile with triangles is a map of its own.
  const bool udim = want_map && writes_map_file(o) && is_udim_pattern(outs.map);
  if (udim) {
    const std::vector<UdimTile> tiles = udim_tiles(scene);
    for (const UdimTile& t : tiles)  // tile 1001 of "ao.1001.png" is the -o path itself, already declared
      if (udim_tile_path(outs.map, t.number()) != outs.map) outputs.add_output(udim_tile_path(outs.map, t.number()), "tile " + std::to_string(t.number()) + " of -o");
    nlohmann::json tile_summary = nlohmann::json::array();
    std::size_t covered = 0;
    for (const UdimTile& t : tiles) {
      const Scene ts = udim_tile_scene(scene, t);
      BakeResult tr;
      {
        ProgressBar bar("bake " + input.filename().string() + " tile " + std::to_string(t.number()), progress);
        if (grouped) {
          tr = bake_in_groups(input, ts, high ? &*high : nullptr, occluders, o, rt, hist, summary, bar.callback());
        } else {
          const TexelCoverage cov = compute_texel_coverage(ts, o.width, o.height);
          if (o.method == "histogram") {
            tr = bake_histogram(ts, cov, hist, bar.callback());
          } else {
            const RayScene tile_rays(ts, bake_bvh_options(ts.triangle_count()));  // the UVs differ per tile, and the baker reads them from its scene
            tr = bake_raytraced(tile_rays, cov, rt, bar.callback());
          }
        }
      }
      if (tr.covered_texels == 0) continue;  // a tile without texels is not written
      if (o.padding > 0) pad(tr.visibility, nearest_valid_texel(tr.mask, o.padding));
      double sum = 0;
      for (std::size_t i = 0; i < tr.mask.size(); ++i)
        if (tr.mask[i]) sum += tr.visibility[i];
      const fs::path path = udim_tile_path(outs.map, t.number());
      outputs.write(path, [&] { write_image(path, tr.visibility, {.png_bits = o.png_bits}); });
      covered += tr.covered_texels;
      tile_summary.push_back({{"tile", t.number()}, {"output", path.string()}, {"texels_covered", tr.covered_texels},
                              {"mean_visibility", sum / static_cast<double>(tr.covered_texels)}});
    }
    bake_ms = clock.lap_ms();
    timings["bake_ms"] = bake_ms;
    summary["udim_tiles"] = tile_summary;
    summary["width"] = o.width;
    summary["height"] = o.height;
    summary["texels_covered"] = covered;
  }
  if (want_map && !udim) {
    const TexelCoverage cov = compute_texel_coverage(scene, o.width, o.height);
    timings["uv_coverage_ms"] = clock.lap_ms();
    for (const std::string& w : cov.warnings()) std::cerr << "warning: " << input.string() << ": " << w << "\n";
    {
      ProgressBar bar("bake " + input.filename().string(), progress);
      if (grouped) r = bake_in_groups(input, scene, high ? &*high : nullptr, occluders, o, rt, hist, summary, bar.callback());
      else if (o.method == "histogram") r = bake_histogram(scene, cov, hist, bar.callback());
      else r = bake_raytraced(ray_scene(), cov, rt, bar.callback());
      bake_ms = clock.lap_ms();
    }
    timings["bake_ms"] = bake_ms;
    map_out = outs.map;
    double sum = 0;
    for (std::size_t i = 0; i < r.mask.size(); ++i)
      if (r.mask[i]) sum += r.visibility[i];
    summary["output"] = map_out.string();
    if (o.width == o.height) summary["size"] = o.width;
    summary["width"] = o.width;
    summary["height"] = o.height;
    summary["texels_covered"] = r.covered_texels;
    summary["mean_visibility"] = r.covered_texels ? sum / static_cast<double>(r.covered_texels) : 1.0;
    summary["texels_per_second"] = bake_ms > 0 ? static_cast<double>(r.covered_texels) / (bake_ms / 1000.0) : 0.0;
    summary["warnings"] = r.warnings;
    summary["overlapping_texels"] = cov.overlapping_texels;
    summary["degenerate_uv_triangles"] = cov.degenerate_uv_triangles;
    summary["stats"] = r.stats;
    if (!o.reference.empty()) {
      // Before padding: only covered texels are compared.
      const Image<float> ref = read_image(o.reference);
      summary["against_reference"] = compare_images(r.visibility, ref, r.mask);
    }
    if (o.method == "histogram") {
      summary["directions"] = r.directions;
      summary["parameters"] = hist;
    } else {
      summary["rays"] = r.rays;
      summary["rays_per_second"] = bake_ms > 0 ? static_cast<double>(r.rays) / (bake_ms / 1000.0) : 0.0;
      if (!high) summary["parameters"] = rt;
    }
    if (o.padding > 0) {
      const Image<std::int32_t> nearest = nearest_valid_texel(r.mask, o.padding);
      pad(r.visibility, nearest);
      if (!r.bent_normal.empty()) pad(r.bent_normal, nearest);
    }
    timings["padding_ms"] = clock.lap_ms();
  }
  std::vector<float> vertex_ao;
  double vertex_ms = 0;
  if (!o.per_vertex.empty()) {
    std::uint64_t nrays = 0;
    {
      ProgressBar bar("per-vertex " + input.filename().string(), progress);
      // With occluders, the scene's meshes come first, so their vertices lead the result.
      Scene with_occluders;
      if (!occluders.empty()) {
        with_occluders = scene;
        for (const Mesh& m : occluders) with_occluders.meshes.push_back(m);
      }
      const Scene& vs = occluders.empty() ? scene : with_occluders;
      if (o.method == "histogram") {
        vertex_ao = bake_vertices_histogram(
            vs, {.directions = hist.directions, .direction_set = hist.direction_set, .resolution = o.vertex_resolution, .seed = o.seed}, bar.callback());
      } else if (occluders.empty()) {
        vertex_ao = bake_vertices_raytraced(ray_scene(), rt, &nrays, bar.callback());
      } else {
        const RayScene occluded(vs);
        vertex_ao = bake_vertices_raytraced(occluded, rt, &nrays, bar.callback());
      }
      vertex_ao.resize(scene.vertex_count());
    }
    vertex_ms = clock.lap_ms();
    timings["per_vertex_ms"] = vertex_ms;
    if (nrays) summary["per_vertex_rays"] = nrays;
  }

  // Writes: staged beside their destinations and renamed together once all are written. The map
  // file is written when -o names it, or under its default name when no other output is asked for
  // (--gltf, --bent-normals, --per-vertex, --miss-mask).
  const bool write_map = writes_map_file(o) && !udim;  // UDIM tiles were written above
  if (!write_map) summary.erase("output");
  if (want_map && !udim) {
    if (write_map && !o.orm.empty()) {
      // The ORM texture with V in its red channel (glTF's occlusion channel); G, B, A and the depth as they were.
      StoredPng packed = read_stored_png(o.orm);
      replace_channel(packed, 0, r.visibility);
      outputs.write(map_out, [&] { write_stored_png(map_out, packed); });
    } else if (write_map) {
      outputs.write(map_out, [&] { write_image(map_out, r.visibility, {.png_bits = o.png_bits}); });
    }
    if (!outs.miss.empty()) {
      Image<float> miss(o.width, o.height, 0.0f);
      for (std::size_t i = 0; i < r.missed.size(); ++i) miss[i] = r.missed[i];
      outputs.write(outs.miss, [&] { write_image(outs.miss, miss, {}); });
    }
    if (!outs.bent.empty() && !r.bent_normal.empty()) {
      Image<Vec3> enc(o.width, o.height, Vec3{0.5f, 0.5f, 0.5f});
      for (std::size_t i = 0; i < enc.size(); ++i)
        if (length(r.bent_normal[i]) > 0) enc[i] = r.bent_normal[i] * 0.5f + Vec3{0.5f, 0.5f, 0.5f};
      outputs.write(outs.bent, [&] { write_rgb_image(outs.bent, enc, {.png_bits = o.png_bits}); });
    }
    if (!outs.gltf.empty()) {
      std::string png;
      if (write_map && (map_out.extension() == ".png" || map_out.extension() == ".PNG")) {
        png = read_bytes(outputs.staged(map_out));
      } else {
        // --png-bits applies to the embedded map too (glTF allows 16-bit PNG).
        const ScratchFile tmp(fs::temp_directory_path() / ("ao-bake-" + std::to_string(::getpid()) + ".png"));
        write_image(tmp.path(), r.visibility, {.png_bits = o.png_bits});
        png = read_bytes(tmp.path());
      }
      outputs.write(outs.gltf, [&] { write_ao_glb(outs.gltf, scene, png, vertex_ao.empty() ? nullptr : &vertex_ao); });
      summary["gltf_output"] = outs.gltf.string();
    }
  }
  if (!outs.per_vertex.empty()) {
    outputs.write(outs.per_vertex, [&] {
      if (lower_extension(outs.per_vertex) == ".glb") write_ao_glb(outs.per_vertex, scene, "", &vertex_ao);
      else write_vertex_ao_ply(outs.per_vertex, scene, vertex_ao);
    });
    summary["per_vertex_output"] = outs.per_vertex.string();
  }
  outputs.commit();
  if (udim && !o.json)
    for (const auto& t : summary["udim_tiles"])
      std::fprintf(stderr, "wrote %s: %s, tile %d, %dx%d, %zu texels covered, mean V = %.4f\n", t["output"].get<std::string>().c_str(), input.filename().string().c_str(),
                   t["tile"].get<int>(), o.width, o.height, t["texels_covered"].get<std::size_t>(), t["mean_visibility"].get<double>());
  if (want_map && write_map && !o.json)
    std::fprintf(stderr, "wrote %s: %s, %s, %dx%d, %zu texels covered, mean V = %.4f, %.0f ms (%.2f M texels/s)\n", map_out.string().c_str(),
                 input.filename().string().c_str(), o.method.c_str(), o.width, o.height, r.covered_texels, summary["mean_visibility"].get<double>(), bake_ms,
                 summary["texels_per_second"].get<double>() / 1e6);
  if (!outs.per_vertex.empty() && !o.json)
    std::fprintf(stderr, "wrote %s: %zu vertices, %.0f ms\n", outs.per_vertex.string().c_str(), vertex_ao.size(), vertex_ms);
  timings["write_ms"] = clock.lap_ms();
  summary["timings"] = timings;
  return summary;
}

// High-to-low options: they need --high, the ray-traced baker, a texture map and one low mesh.
void check_high_to_low_options(BakeOptions& o) {
  const int grouping = (o.match_by_name ? 1 : 0) + (o.groups.empty() ? 0 : 1) + (o.self_occlusion ? 1 : 0);
  if (grouping > 1) throw InputError("--match-by-name, --group and --self-occlusion: give one way of forming bake groups");
  if (o.match_by_name && o.high.empty()) throw InputError("--match-by-name needs --high: it pairs low meshes NAME_low with high meshes NAME_high");
  if (grouping > 0 && !o.per_vertex.empty()) throw InputError("--per-vertex with bake groups: per-vertex AO is baked with every mesh occluding; drop the grouping");
  if (o.floor && o.method_given && o.method == "histogram")
    throw InputError("--floor needs --method raytraced: the histogram baker renders views covering the whole scene, and a floor 20 model diagonals "
                     "wide would make each view's pixels 400 times as many");
  if (o.floor) o.method = "raytraced";
  if (o.high.empty()) {
    if (!o.cage.empty() || o.h2l.cage_extrusion || o.h2l.max_front || o.h2l.max_back || !o.miss_mask.empty())
      throw InputError("--cage, --cage-extrusion, --max-front, --max-back and --miss-mask need --high (the high-poly mesh to bake from)");
    return;
  }
  if (o.method_given && o.method == "histogram")
    throw InputError(
        "--high needs --method raytraced: the histogram baker scatters each view's pixels into the texels of the surface it sees, "
        "and pixels of the high mesh have no texel in the low mesh's map without a cage ray per pixel, which is the ray-traced baker");
  o.method = "raytraced";
  if (!o.per_vertex.empty()) throw InputError("--per-vertex with --high: per-vertex AO is baked from the mesh itself; bake the high mesh's map, or drop --high");
  if (!o.cage.empty() && o.h2l.cage_extrusion) throw InputError("--cage and --cage-extrusion: give one (an explicit cage, or the low mesh pushed out by a distance)");
  if (!o.miss_mask.empty() && !is_supported_image_path(o.miss_mask))
    throw InputError(o.miss_mask + ": unknown image extension (supported: " + supported_image_extensions() + ")");
  o.h2l.validate();
}

// --orm: one mesh, a PNG map output, a texture with red, green and blue; the map takes its size
// unless -s is given (then they must agree) and its bit depth (so --png-bits does not apply).
void check_orm(BakeOptions& o, bool batch) {
  if (batch) throw InputError("--orm packs the map of one mesh into one texture: give one mesh, not several or a folder");
  if (!wants_map(o) || !writes_map_file(o)) throw InputError("--orm writes the map file: give -o out.png (it is not written with only --gltf, --bent-normals or --per-vertex)");
  if (!o.output.empty() && lower_extension(o.output) != ".png") throw InputError(o.output + ": with --orm the map is the ORM texture with AO in red, a PNG; give -o a .png name");
  if (o.png_bits_given) throw InputError("--png-bits with --orm: the output keeps the ORM texture's own bit depth; drop --png-bits");
  const StoredPng orm = read_stored_png(o.orm);
  if (orm.channels < 3)
    throw InputError(o.orm + ": --orm needs an RGB or RGBA texture (occlusion, roughness, metalness in R, G, B); this one is greyscale");
  if (!o.size_given) {
    o.width = orm.width;
    o.height = orm.height;
  } else if (orm.width != o.width || orm.height != o.height) {
    throw InputError(o.orm + ": the ORM texture is " + std::to_string(orm.width) + "x" + std::to_string(orm.height) + " and the map -s " + std::to_string(o.width) +
                     "x" + std::to_string(o.height) + "; give -s " + std::to_string(orm.width) + "x" + std::to_string(orm.height) + " or leave -s out");
  }
}

int run_bake(BakeOptions o, const GlobalOptions& global) {
  if (o.method != "histogram" && o.method != "raytraced") throw InputError("--method: expected histogram or raytraced, got '" + o.method + "'");
  check_high_to_low_options(o);
  const std::vector<std::string>& foreign = o.method == "histogram" ? o.raytraced_only : o.histogram_only;
  if (!foreign.empty())
    throw InputError(foreign.front() + " does not apply to --method " + o.method + " (it is a " + (o.method == "histogram" ? "raytraced" : "histogram") +
                     " option); drop it or choose --method " + (o.method == "histogram" ? "raytraced" : "histogram"));
  if (!o.max_distance && std::find(o.raytraced_only.begin(), o.raytraced_only.end(), "--membership") != o.raytraced_only.end())
    throw InputError("--membership needs --max-distance: with unlimited distance every occluder counts fully (there is no falloff)");
  if (o.max_distance) {
    const auto m = parse_membership(o.membership);
    if (!m || *m == Membership::Exp) throw InputError("--membership: use step, linear, sqrt or cubic for baking, got '" + o.membership + "'");
  }
  if (o.uv_set < 0 || o.uv_set > 7) throw InputError("--uv-set must be in [0, 7] (UV sets count from 0)");
  if (o.png_bits != 8 && o.png_bits != 16) throw InputError("--png-bits must be 8 or 16");
  if (o.padding < 0 || o.padding > 1024) throw InputError("--padding must be in [0, 1024] texels");
  const auto ds = parse_direction_set(o.direction_set);
  if (!ds) throw InputError("--direction-set: expected fibonacci or gaussian, got '" + o.direction_set + "'");
  o.hist.direction_set = *ds;
  const auto norm = parse_normalization(o.normalization);
  if (!norm) throw InputError("--normalization: expected area or max, got '" + o.normalization + "'");
  o.hist.normalization = *norm;
  o.hist.bent_normals = o.rt.bent_normals = !o.bent.empty();
  o.rt.normal = parse_surface_normal(o.normal);
  if (o.denoise_given && !wants_map(o)) throw InputError("--denoise filters maps; per-vertex AO is not filtered, so drop --denoise");
  // High to low bakes the high mesh's detail, often a few texels wide, which the filter would
  // soften: filtered only when asked (docs/methods/bake.md, "Denoising").
  o.rt.denoise = wants_map(o) ? o.denoise : 0.0f;
  o.rt.validate();  // before any mesh is loaded: --samples, --offset, --denoise
  o.hist.validate();
  const auto size = parse_map_size(o.size_text);
  if (!size) throw InputError("--size: expected N or WIDTHxHEIGHT (2048x1024), each in [1, 16384] texels, got '" + o.size_text + "'");
  o.width = size->first;
  o.height = size->second;
  const std::vector<fs::path> inputs = expand_inputs(o.inputs);
  if (inputs.empty()) throw InputError("no mesh files to bake (folders are searched for .obj .ply .off .stl .gltf .glb)");
  const bool batch = inputs.size() > 1 || fs::is_directory(o.inputs.front());
  if (batch && !o.high.empty()) throw InputError("--high bakes one low mesh: give one low-poly mesh file, not " + std::to_string(inputs.size()) + " or a folder");
  check_output_names(o, batch);
  if (!o.orm.empty()) check_orm(o, batch);
  if (is_udim_pattern(o.output)) {
    const std::pair<bool, const char*> single_map_options[] = {{!o.gltf.empty(), "--gltf (a material takes one occlusion texture)"},
                                                              {!o.bent.empty(), "--bent-normals"},
                                                              {!o.miss_mask.empty(), "--miss-mask"},
                                                              {!o.orm.empty(), "--orm"},
                                                              {!o.reference.empty(), "--reference"}};
    for (const auto& [given, what] : single_map_options)
      if (given) throw InputError(o.output + ": UDIM tiles are written for the map only; " + what + " needs a single map, drop it or the tile pattern");
  }
  // Every output of the run is checked against every input and every other output before any
  // mesh is loaded (each mesh's outputs are then one transaction of their own).
  {
    OutputSet all;
    for (const fs::path& in : inputs) all.add_input(in, "the mesh " + in.string());
    for (const fs::path& in : inputs) declare(all, in, o, outputs_of(in, o, batch), batch);
  }
  if (wants_map(o)) {
    const int threads = static_cast<int>(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
    check_memory(estimate_bake_memory({.size = o.width, .height = o.height, .histogram = o.method == "histogram", .bent_normals = !o.bent.empty(),
                                       .pixels_per_texel = o.hist.pixels_per_texel, .threads = threads, .denoise = o.rt.denoise > 0}),
                 "ao bake: a " + std::to_string(o.width) + "x" + std::to_string(o.height) + " map");
  }
  if (!batch) {
    const nlohmann::json s = bake_one(inputs.front(), o, false, global);
    if (o.json) std::cout << s.dump(2) << "\n";
    return 0;
  }
  nlohmann::json all = nlohmann::json::array();
  int failed = 0;
  // In a log (stderr not a terminal, so no progress bars) each mesh gets a start and an end line.
  const bool log_lines = !global.quiet && !stderr_is_terminal();
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const fs::path& in = inputs[i];
    const std::string head = "mesh " + std::to_string(i + 1) + " of " + std::to_string(inputs.size()) + ": " + in.filename().string();
    if (log_lines) std::fprintf(stderr, "%s ...\n", head.c_str());
    Stopwatch mesh_clock;
    bool ok = false;
    try {
      all.push_back(bake_one(in, o, true, global));
      ok = true;
    } catch (const InputError& e) {
      ++failed;
      std::fprintf(stderr, "ao: error: %s\n", e.what());
      all.push_back({{"input", in.string()}, {"error", e.what()}});
    } catch (const SystemError& e) {
      ++failed;
      std::fprintf(stderr, "ao: error: %s\n", e.what());
      all.push_back({{"input", in.string()}, {"error", e.what()}});
    }
    if (log_lines) std::fprintf(stderr, "%s ... %s in %.1f s\n", head.c_str(), ok ? "done" : "failed", mesh_clock.lap_ms() / 1000.0);
  }
  if (o.json) std::cout << all.dump(2) << "\n";
  if (failed) std::fprintf(stderr, "ao bake: %d of %zu meshes failed\n", failed, inputs.size());
  return failed ? 1 : 0;
}

}  // namespace

void add_bake_command(CLI::App& app, const GlobalOptions& global, std::function<int()>& action) {
  auto o = std::make_shared<BakeOptions>();
  CLI::App* cmd = app.add_subcommand("bake", "Bake an AO map (mesh UV space), per-vertex AO or a glTF with the map, for one or more meshes.");
  cmd->add_option("meshes", o->inputs, "Mesh files (OBJ, PLY, OFF, STL, glTF/GLB) or folders of them; several are baked in turn")->required()->type_name("MESH");
  cmd->add_option("-o,--output", o->output, "AO map: .png or .tif (8/16 bit), .tga (8 bit), .jpg (8 bit and LOSSY: block artefacts in the data), .exr (float); linear. A name with <UDIM> "
                  "or .1001. writes one map per UDIM tile (ao.<UDIM>.png -> ao.1001.png, ao.1002.png, ...). Default <mesh>-ao.png; in a batch, <mesh>-<name>");
  cmd->add_option("--out-dir", o->out_dir, "Folder for the outputs of a batch (default: beside each mesh)");
  CLI::Option* method = cmd->add_option("-m,--method", o->method, "raytraced (Embree, inside-out; default) or histogram (outside-in, McGraw & Sowers; unlimited distance)")->capture_default_str();
  CLI::Option* size_opt = cmd->add_option("-s,--size", o->size_text, "Map size in texels: N (N x N) or WIDTHxHEIGHT (2048x1024), each in [1, 16384]")->capture_default_str();
  cmd->add_option("--uv-set", o->uv_set, "UV set to bake into, from 0 (glTF TEXCOORD_n); --gltf writes it as TEXCOORD_0 for OBJ/PLY/STL, keeps it (texCoord n) for glTF")->capture_default_str();
  cmd->add_option("-d,--directions", o->hist.directions, "histogram: directions on the sphere [1, 65536]")->capture_default_str();
  cmd->add_option("--direction-set", o->direction_set, "histogram: fibonacci (stratified) or gaussian (the paper's)")->capture_default_str();
  cmd->add_option("--pixels-per-texel", o->hist.pixels_per_texel, "histogram: view resolution, pixels per texel edge (0, 8]")->capture_default_str();
  cmd->add_option("--point-size", o->hist.point_size, "histogram: splat size in texels, >1 smooths (paper sec. 3.2) [1, 16]")->capture_default_str();
  cmd->add_option("--normalization", o->normalization, "histogram: area (exact, absolute V) or max (the paper's: max V = 1)")->capture_default_str();
  cmd->add_option("--min-samples", o->hist.min_samples,
                  "histogram: texels expected to get fewer pixel samples than this (chart slivers) copy the nearest texel that gets enough; 0 = off")
      ->capture_default_str();
  cmd->add_flag("--seam-fix,!--no-seam-fix", o->hist.seam_fix, "histogram: refill poorly covered chart-border texels from their neighbours (paper sec. 3.3; default on)");
  cmd->add_option("--samples,--spp", o->rt.samples, "raytraced: rays per texel (per vertex with --per-vertex)")->capture_default_str();
  auto* denoise_opt = cmd->add_option("--denoise", o->denoise,
                                      "raytraced maps: sigma in texels of the texture-space filter that averages the noise of texels that are "
                                      "neighbours on the surface (not across charts or creases); 0 = off, the plain ray-traced estimate [0, 4]")
                          ->capture_default_str();
  cmd->add_option("--max-distance", o->max_distance, "raytraced: occluders count only within this distance R, world units (default: unlimited)");
  cmd->add_option("--membership", o->membership, "raytraced with --max-distance: falloff step, linear, sqrt or cubic")->capture_default_str();
  cmd->add_option("--offset", o->rt.offset, "raytraced: ray origin offset along the face normal, world units (0: scale-free, a few float spacings of the coordinates; docs/methods/raytraced.md)")->capture_default_str();
  cmd->add_option("--normal", o->normal,
                  "raytraced: hemisphere about the interpolated shading normal (default: the smooth surface the mesh stands for) or the "
                  "triangle's geometric normal (per vertex: the area-weighted mean over its triangles); the histogram baker integrates the "
                  "whole sphere of views and takes no normal")
      ->type_name("shading|geometric")
      ->capture_default_str();
  cmd->add_flag("--ignore-back-faces", o->rt.ignore_back_faces, "raytraced: rays pass through back faces (xNormal/Substance 'ignore backface')");
  cmd->add_option("--padding", o->padding, "Fill texels up to this far outside the charts from the nearest chart texel [0, 1024]")->capture_default_str();
  CLI::Option* png_bits_opt = cmd->add_option("--png-bits", o->png_bits, "PNG and TIFF bit depth, 8 or 16 (TGA and JPEG are 8-bit)")->capture_default_str();
  cmd->add_option("--orm", o->orm,
                  "Write the map into the red channel of this ORM texture (PNG, RGB/RGBA, 8/16 bit): -o gets a copy with AO in R and G, B, A, depth "
                  "as they were; the map takes its size")
      ->type_name("PNG");
  cmd->add_option("--bent-normals", o->bent, "Also write the bent normals (average open direction, world space, n*0.5+0.5) to this image");
  cmd->add_option("--per-vertex", o->per_vertex, "Also (or, without -o/--gltf, only) write per-vertex AO: .ply (colour + float quality) or .glb (glTF COLOR_0)");
  cmd->add_option("--vertex-resolution", o->vertex_resolution, "histogram --per-vertex: view size in pixels [64, 8192]")->capture_default_str();
  cmd->add_option("--gltf", o->gltf, "Also write a .glb of the mesh with the map as its material's occlusion texture; a glTF input keeps its nodes, instances and "
                  "materials, one map per glTF mesh (docs/bake.md)");
  cmd->add_option("--reference", o->reference, "Compare the map with this reference map (EXR/PNG, same size) over covered texels; RMSE etc. in --json");
  cmd->add_option("--seed", o->seed, "Seed of directions / sample sets")->capture_default_str();
  cmd->add_flag("--json", o->json, "Print a JSON summary (texels covered, directions or rays, timings, texels/s, rays/s) on stdout");
  cmd->add_option("--high", o->high, "High to low: bake the AO of this high-poly mesh into the low mesh's UVs (repeatable; ray-traced)")->type_name("MESH");
  cmd->add_option("--cage", o->cage, "High to low: cage mesh (the low mesh's topology, pushed out); rays start on it and travel inwards");
  cmd->add_option("--cage-extrusion", o->h2l.cage_extrusion,
                  "High to low: without --cage, push the low mesh out along its smoothed normals by this distance, world units (default 0.01 x diagonal)");
  cmd->add_option("--max-front", o->h2l.max_front, "High to low: rays start this far outside the low surface, world units (default: at the cage)");
  cmd->add_option("--max-back", o->h2l.max_back, "High to low: rays look this far inside the low surface, world units (default: the cage distance)");
  cmd->add_option("--cage-points", o->h2l.cage_points,
                  "High to low: cage rays per texel, stratified over its patch, each carrying an equal share of the texel's AO rays [1, 1048576]")
      ->capture_default_str();
  cmd->add_option("--occluder", o->occluders, "Mesh that occludes but is not baked (repeatable)")->type_name("MESH");
  cmd->add_flag("--floor", o->floor, "Add a ground plane under the model (y up, at its lowest point) as an occluder");
  cmd->add_option("--group", o->groups, "Bake group: comma-separated mesh names that occlude each other and nothing else (repeatable; meshes not named form one more group)")
      ->type_name("NAMES");
  cmd->add_flag("--self-occlusion", o->self_occlusion, "Each mesh is occluded only by itself (and --occluder, --floor)");
  cmd->add_flag("--match-by-name", o->match_by_name, "With --high: low mesh NAME_low bakes only from high meshes NAME_high (or NAME), Substance's convention");
  cmd->add_option("--miss-mask", o->miss_mask, "High to low: write 1 where every cage ray of a texel missed the high mesh (those texels are filled from neighbours)");
  // Options that only one baker reads: giving them to the other is an error, not silently ignored.
  std::vector<CLI::Option*> histogram_only, raytraced_only;
  for (const char* name : {"--directions", "--direction-set", "--pixels-per-texel", "--point-size", "--normalization", "--min-samples", "--seam-fix",
                           "--vertex-resolution"})
    histogram_only.push_back(cmd->get_option(name));
  for (const char* name : {"--samples", "--max-distance", "--membership", "--offset", "--ignore-back-faces", "--normal", "--denoise"})
    raytraced_only.push_back(cmd->get_option(name));
  cmd->callback([o, method, size_opt, png_bits_opt, denoise_opt, histogram_only, raytraced_only, &global, &action] {
    o->method_given = method->count() > 0;
    o->denoise_given = denoise_opt->count() > 0;
    o->size_given = size_opt->count() > 0;
    o->png_bits_given = png_bits_opt->count() > 0;
    for (const CLI::Option* opt : histogram_only)
      if (opt->count() > 0) o->histogram_only.push_back(opt->get_name());
    for (const CLI::Option* opt : raytraced_only)
      if (opt->count() > 0) o->raytraced_only.push_back(opt->get_name());
    action = [o, &global] { return run_bake(*o, global); };
  });
}

}  // namespace ao::cli
