// SPDX-License-Identifier: Apache-2.0
// ao bake: parses the options into a BakeRequest (ao/jobs/bake.h), runs it, and prints the JSON
// summary; exit status 1 when a mesh of a batch failed.
#include <cstdio>
#include <iostream>

#include <CLI/CLI.hpp>

#include "ao/bake/denoise.h"
#include "ao/core/error.h"
#include "ao/core/params.h"
#include "ao/core/params_table.h"
#include "ao/jobs/bake.h"
#include "common.h"
#include "subcommands.h"

namespace ao::cli {

namespace {

/// A baker's default of a parameter the command line gives by name, as the baker's table names it.
template <class T>
std::string default_name(const ParamTable<T>& table, const char* key) {
  return table.to_json(T{}).at(key).template get<std::string>();
}

struct BakeOptions {
  BakeRequest request;  ///< Filled directly where the types allow.
  std::string method{to_string(BakeRequest{}.method)};
  std::string size = "1024";
  std::vector<std::string> groups;  ///< "a,b,c" each.
  std::string direction_set = default_name(histogram_param_table(), "direction_set");
  std::string normalization = default_name(histogram_param_table(), "normalization");
  std::string normal = default_name(raytraced_bake_param_table(), "normal");
  std::string membership = default_name(raytraced_bake_param_table(), "membership");
  std::string texel_sampling = default_name(raytraced_bake_param_table(), "texel_sampling");
  std::string bent_normal_space{to_string(BakeRequest{}.bent_normal_space)};
  std::uint32_t seed = RaytracedBakeParams{}.seed;  ///< Both bakers' (the same default).
  bool json = false;
  // Options given that only one baker reads, by name ("--directions", ...).
  std::vector<std::string> histogram_only, raytraced_only;
  bool size_given = false;
};

BakeRequest make_request(BakeOptions& o) {
  BakeRequest r = o.request;
  r.method = baker_from_name(o.method);
  // Options that only one baker reads: giving them to the other is an error, not silently ignored.
  const std::vector<std::string>& foreign = r.method == Baker::Histogram ? o.raytraced_only : o.histogram_only;
  if (!foreign.empty()) {
    const std::string other(to_string(r.method == Baker::Histogram ? Baker::Raytraced : Baker::Histogram));
    throw InputError(foreign.front() + " does not apply to --method " + o.method + " (it is a " + other + " option); drop it or choose --method " + other);
  }
  if (o.size_given) r.size = parse_map_size(o.size);
  r.bent_normal_space = bent_normal_space_from_name(o.bent_normal_space);
  for (const std::string& g : o.groups) r.groups.push_back(split(g, ','));
  // The options given as names go through the bakers' tables, which name the valid values.
  raytraced_bake_param_table().from_json({{"seed", o.seed}, {"normal", o.normal}, {"membership", o.membership}, {"texel_sampling", o.texel_sampling}},
                                         r.raytraced);
  histogram_param_table().from_json({{"seed", o.seed}, {"direction_set", o.direction_set}, {"normalization", o.normalization}}, r.histogram);
  return r;
}

int run(BakeOptions& o, const GlobalOptions& global) {
  const BakeRequest request = make_request(o);
  if (global.request_only) return 0;
  StderrReporter report(global, o.json);
  const BakeBatchResult result = run_bake(request, report.reporter());
  report.end_stage();
  if (o.json) {
    nlohmann::json all = nlohmann::json::array();
    for (const MeshBake& m : result.meshes) all.push_back(m.summary);
    std::cout << (result.batch ? all : all.front()).dump(2) << "\n";
  }
  if (result.failed) std::fprintf(stderr, "ao bake: %d of %zu meshes failed\n", result.failed, result.meshes.size());
  return result.failed ? 1 : 0;
}

void add_histogram_options(CLI::App& cmd, BakeOptions& o) {
  HistogramParams& h = o.request.histogram;
  const ParamSchema table(histogram_param_table());
  const auto help = [&](std::string_view name) { return param_help(table, name, "histogram: "); };
  cmd.add_option("-d,--directions", h.directions, help("directions"))->capture_default_str();
  cmd.add_option("--direction-set", o.direction_set, help("direction_set"))->capture_default_str();
  cmd.add_option("--pixels-per-texel", h.pixels_per_texel, help("pixels_per_texel"))->capture_default_str();
  cmd.add_option("--point-size", h.point_size, help("point_size"))->capture_default_str();
  cmd.add_option("--normalization", o.normalization, help("normalization"))->capture_default_str();
  cmd.add_option("--min-samples", h.min_samples, help("min_samples"))->capture_default_str();
  cmd.add_flag("--seam-fix,!--no-seam-fix", h.seam_fix, help("seam_fix") + " (default on)");
  cmd.add_option("--vertex-resolution", o.request.vertex_resolution, "histogram --per-vertex: view size in pixels [64, 8192]")->capture_default_str();
}

void add_raytraced_options(CLI::App& cmd, BakeOptions& o) {
  RaytracedBakeParams& rt = o.request.raytraced;
  const ParamSchema table(raytraced_bake_param_table());
  const auto help = [&](std::string_view name) { return param_help(table, name, "raytraced: "); };
  cmd.add_option("--samples,--spp", rt.samples, help("samples"))->capture_default_str();
  cmd.add_option("--denoise", o.request.denoise,
                 help("denoise") + ": averages the noise of texels that are neighbours on the surface (not across charts or creases)")
      ->default_str(float_text(kDefaultBakeDenoise));
  cmd.add_option("--max-distance", rt.max_distance, help("max_distance"));
  cmd.add_option("--membership", o.membership, help("membership"))->capture_default_str();
  cmd.add_option("--texel-sampling", o.texel_sampling, help("texel_sampling"))->type_name("area|centre")->capture_default_str();
  cmd.add_option("--offset", rt.offset, help("offset"))->capture_default_str();
  cmd.add_option("--normal", o.normal,
                 help("normal") + " (per vertex: the area-weighted mean over its triangles); the histogram baker integrates the whole "
                 "sphere of views and takes no normal")
      ->type_name("shading|geometric")
      ->capture_default_str();
  cmd.add_flag("--ignore-back-faces", rt.ignore_back_faces, help("ignore_back_faces"));
  cmd.add_option("--spread-angle", rt.spread_angle, help("spread_angle") + " (every map: AO, bent normals, thickness, cavity)")->capture_default_str();
  cmd.add_flag("--relative-distance", rt.relative_distance,
               "raytraced: --max-distance is a fraction of the diagonal of the baked meshes' bounding box (occluders and --floor excluded)");
}

void add_high_to_low_options(CLI::App& cmd, BakeOptions& o) {
  BakeRequest& r = o.request;
  const ParamSchema table(high_to_low_param_table());
  const auto help = [&](std::string_view name) { return param_help(table, name, "High to low: "); };
  cmd.add_option("--high", r.high, "High to low: bake the AO of this high-poly mesh into the low mesh's UVs (repeatable; ray-traced)")->type_name("MESH");
  cmd.add_option("--cage", r.cage, "High to low: cage mesh (the low mesh's topology, pushed out); rays start on it and travel inwards");
  cmd.add_option("--cage-extrusion", r.high_to_low.cage_extrusion, help("cage_extrusion"));
  cmd.add_option("--max-front", r.high_to_low.max_front, help("max_front"));
  cmd.add_option("--max-back", r.high_to_low.max_back, help("max_back"));
  cmd.add_option("--cage-points", r.high_to_low.cage_points, help("cage_points"))->capture_default_str();
  cmd.add_option("--occluder", r.occluders, "Mesh that occludes but is not baked (repeatable)")->type_name("MESH");
  cmd.add_flag("--floor", r.floor, "Add a ground plane under the model (y up, at its lowest point) as an occluder");
  cmd.add_option("--group", o.groups, "Bake group: comma-separated mesh names that occlude each other and nothing else (repeatable; meshes not named form one more group)")
      ->type_name("NAMES");
  cmd.add_flag("--self-occlusion", r.self_occlusion, "Each mesh is occluded only by itself (and --occluder, --floor)");
  cmd.add_flag("--match-by-name", r.match_by_name, "With --high: low mesh NAME_low bakes only from high meshes NAME_high (or NAME), Substance's convention");
  cmd.add_option("--miss-mask", r.outputs.miss_mask, "High to low: write 1 where every cage ray of a texel missed the high mesh (those texels are filled from neighbours)");
}

void add_output_options(CLI::App& cmd, BakeOptions& o) {
  BakeRequest& r = o.request;
  cmd.add_option("-o,--output", r.outputs.map,
                 "AO map: .png or .tif (8/16 bit), .tga (8 bit), .jpg (8 bit and LOSSY: block artefacts in the data), .exr (float); linear. A name with <UDIM> "
                 "or .1001. writes one map per UDIM tile (ao.<UDIM>.png -> ao.1001.png, ao.1002.png, ...). Default <mesh>-ao.png; in a batch, <mesh>-<name>");
  cmd.add_option("--out-dir", r.out_dir, "Folder for the outputs of a batch (default: beside each mesh)");
  cmd.add_option("--png-bits", r.outputs.png_bits, "PNG and TIFF bit depth, 8 or 16 (TGA and JPEG are 8-bit)")->default_str("8");
  cmd.add_flag("--provenance", r.outputs.provenance,
               "Also write beside each output FILE its record FILE.ao.json: ao's version and SIMD target, the inputs' SHA-256, every setting "
               "(docs/cluster.md, \"Provenance\")");
  cmd.add_option("--orm", r.orm,
                 "Write the map into the red channel of this ORM texture (PNG, RGB/RGBA, 8/16 bit): -o gets a copy with AO in R and G, B, A, depth "
                 "as they were; the map takes its size")
      ->type_name("PNG");
  cmd.add_option("--bent-normals", r.outputs.bent_normals, "Also write the bent normals (average open direction, world space, n*0.5+0.5) to this image");
  cmd.add_option("--bent-normals-space", o.bent_normal_space,
                 "world: the direction as is; tangent: in the tangent space of the UV layout (MikkTSpace frames, as Blender, glTF and engines "
                 "build them), what engines read for specular occlusion")
      ->type_name("world|tangent")
      ->capture_default_str();
  cmd.add_option("--thickness", r.outputs.thickness,
                 "Also write a thickness map (ray-traced): rays into the mesh, the mean of min(d/R, 1), R = --thickness-distance; white where the "
                 "mesh is at least R deep behind the surface, darker where it is thinner (subsurface, translucency)");
  cmd.add_option("--thickness-distance", r.thickness_distance, "R of --thickness as a fraction of the baked meshes' bounding-box diagonal (0, 10]")
      ->capture_default_str();
  cmd.add_option("--cavity", r.outputs.cavity,
                 "Also write a cavity map (ray-traced): AO with R = --cavity-distance, so that only small creases darken");
  cmd.add_option("--cavity-distance", r.cavity_distance, "R of --cavity as a fraction of the baked meshes' bounding-box diagonal (0, 10]")
      ->capture_default_str();
  cmd.add_option("--per-vertex", r.outputs.per_vertex, "Also (or, without -o/--gltf, only) write per-vertex AO: .ply (colour + float quality) or .glb (glTF COLOR_0)");
  cmd.add_option("--gltf", r.outputs.gltf, "Also write a .glb of the mesh with the map as its material's occlusion texture; a glTF input keeps its nodes, instances and "
                 "materials, one map per glTF mesh (docs/bake.md)");
  cmd.add_option("--reference", r.reference, "Compare the map with this reference map (EXR/PNG, same size) over covered texels; RMSE etc. in --json");
}

}  // namespace

void add_bake_command(CLI::App& app, const GlobalOptions& global, std::function<int()>& action) {
  auto o = std::make_shared<BakeOptions>();
  CLI::App* cmd = app.add_subcommand("bake", "Bake an AO map (mesh UV space), per-vertex AO or a glTF with the map, for one or more meshes.");
  cmd->add_option("meshes", o->request.inputs, "Mesh files (OBJ, PLY, OFF, STL, glTF/GLB) or folders of them; several are baked in turn")->required()->type_name("MESH");
  cmd->add_option("-m,--method", o->method, "raytraced (Embree, inside-out; default) or histogram (outside-in, McGraw & Sowers; unlimited distance)")->capture_default_str();
  CLI::Option* size_opt = cmd->add_option("-s,--size", o->size, "Map size in texels: N (N x N) or WIDTHxHEIGHT (2048x1024), each in [1, 16384]")->capture_default_str();
  cmd->add_option("--uv-set", o->request.uv_set, "UV set to bake into, from 0 (glTF TEXCOORD_n); --gltf writes it as TEXCOORD_0 for OBJ/PLY/STL, keeps it (texCoord n) for glTF")->capture_default_str();
  add_histogram_options(*cmd, *o);
  add_raytraced_options(*cmd, *o);
  cmd->add_option("--padding", o->request.padding, "Fill texels up to this far outside the charts from the nearest chart texel [0, 1024]")->capture_default_str();
  add_output_options(*cmd, *o);
  cmd->add_option("--seed", o->seed, "Seed of directions / sample sets")->capture_default_str();
  cmd->add_flag("--json", o->json, "Print a JSON summary (texels covered, directions or rays, timings, texels/s, rays/s) on stdout");
  add_high_to_low_options(*cmd, *o);
  std::vector<CLI::Option*> histogram_only, raytraced_only;
  for (const char* name : {"--directions", "--direction-set", "--pixels-per-texel", "--point-size", "--normalization", "--min-samples", "--seam-fix",
                           "--vertex-resolution"})
    histogram_only.push_back(cmd->get_option(name));
  for (const char* name : {"--samples", "--max-distance", "--membership", "--offset", "--ignore-back-faces", "--normal", "--denoise", "--spread-angle",
                           "--relative-distance", "--texel-sampling"})
    raytraced_only.push_back(cmd->get_option(name));
  cmd->callback([o, size_opt, histogram_only, raytraced_only, &global, &action] {
    o->size_given = size_opt->count() > 0;
    for (const CLI::Option* opt : histogram_only)
      if (opt->count() > 0) o->histogram_only.push_back(opt->get_name());
    for (const CLI::Option* opt : raytraced_only)
      if (opt->count() > 0) o->raytraced_only.push_back(opt->get_name());
    action = [o, &global] { return run(*o, global); };
  });
}

}  // namespace ao::cli
