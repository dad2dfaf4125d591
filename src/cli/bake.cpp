// ao bake: mesh(es) with UVs -> AO map (PNG/EXR), optionally per-vertex AO (PLY) and a .glb with
// the map as the occlusion texture. Several meshes or a folder are baked in turn; a failure is
// reported and the rest are still baked (exit status 1 if any failed).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <CLI/CLI.hpp>
#include <unistd.h>

#include "ao/bake/histogram.h"
#include "ao/bake/padding.h"
#include "ao/bake/per_vertex.h"
#include "ao/bake/raytraced_bake.h"
#include "ao/core/error.h"
#include "ao/eval/metrics.h"
#include "ao/io/gltf_export.h"
#include "ao/io/image_io.h"
#include "ao/io/mesh_io.h"
#include "ao/io/ply_export.h"
#include "ao/reference/ray_scene.h"
#include "common.h"
#include "subcommands.h"

namespace ao::cli {

namespace {

namespace fs = std::filesystem;

struct BakeOptions {
  std::vector<std::string> inputs;
  std::string output, out_dir, per_vertex, gltf, bent, reference;
  std::string method = "histogram";
  int size = 1024;
  int uv_set = 0;
  int padding = kDefaultPadding;
  int png_bits = 8;
  bool json = false;
  HistogramParams hist;
  std::string direction_set = "fibonacci", normalization = "area";
  RaytracedBakeParams rt;
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
  if (!o.per_vertex.empty() && lower_extension(o.per_vertex) != ".ply")
    throw InputError(o.per_vertex + ": --per-vertex writes PLY, give it a .ply name");
  if (!o.gltf.empty() && lower_extension(o.gltf) != ".glb") throw InputError(o.gltf + ": --gltf writes binary glTF, give it a .glb name");
  if (!o.out_dir.empty() && !fs::is_directory(o.out_dir)) throw InputError("--out-dir: " + o.out_dir + " is not a directory");
  if (batch) return;  // outputs go to --out-dir or beside each mesh
  for (const std::string& out : {o.output, o.bent, o.per_vertex, o.gltf}) {
    if (out.empty()) continue;
    const fs::path parent = fs::path(out).parent_path();
    if (!parent.empty() && !fs::is_directory(parent)) throw InputError(out + ": folder " + parent.string() + " does not exist");
  }
}

nlohmann::json bake_one(const fs::path& input, const BakeOptions& o, bool batch, const GlobalOptions& global) {
  Stopwatch clock;
  nlohmann::json timings;
  const bool progress = !global.quiet && stderr_is_terminal();
  Scene scene = load_scene_file(input, {.uv_set = o.uv_set});
  for (const std::string& w : scene.warnings) std::cerr << "warning: " << input.string() << ": " << w << "\n";
  // A glTF input keeps its materials (factors, textures, ...) in the --gltf output, with the map added.
  std::optional<GltfSource> source;
  if (!o.gltf.empty() && is_gltf_file(input)) {
    source = load_gltf_materials(input, scene, o.uv_set);
    for (const std::string& w : source->warnings) std::cerr << "warning: " << input.string() << ": " << w << "\n";
  }
  timings["load_ms"] = clock.lap_ms();
  nlohmann::json summary = {{"input", input.string()}, {"method", o.method}, {"triangles", scene.triangle_count()}, {"vertices", scene.vertex_count()}};
  RaytracedBakeParams rt = o.rt;
  rt.seed = o.seed;
  rt.max_distance = o.max_distance;
  if (o.max_distance) {
    const auto m = parse_membership(o.membership);
    if (!m || *m == Membership::Exp) throw InputError("--membership: use step, linear, sqrt or cubic for baking, got '" + o.membership + "'");
    rt.membership = *m;
  }
  HistogramParams hist = o.hist;
  hist.seed = o.seed;
  if (o.method == "histogram" && o.max_distance)
    throw InputError("--max-distance needs --method raytraced: the histogram baker sees occluders at any distance (paper eq. 1)");
  std::unique_ptr<RayScene> rays;
  auto ray_scene = [&]() -> RayScene& {
    if (!rays) {
      rays = std::make_unique<RayScene>(scene);
      timings["bvh_ms"] = clock.lap_ms();
    }
    return *rays;
  };

  const bool want_map = o.per_vertex.empty() || !o.output.empty() || !o.gltf.empty();
  const bool has_uv = std::any_of(scene.meshes.begin(), scene.meshes.end(), [](const Mesh& m) { return !m.uvs.empty(); });
  if (want_map && !has_uv)
    throw InputError(input.string() + ": the mesh has no UV coordinates, so it cannot be baked to a texture; use --per-vertex out.ply for per-vertex AO");

  // Everything is computed first and written at the end, so a mesh that fails half-way (or a
  // per-vertex bake that fails after the map) leaves no partial set of outputs behind.
  BakeResult r;
  double bake_ms = 0;
  fs::path map_out;
  if (want_map) {
    const TexelCoverage cov = compute_texel_coverage(scene, o.size);
    timings["uv_coverage_ms"] = clock.lap_ms();
    for (const std::string& w : cov.warnings()) std::cerr << "warning: " << input.string() << ": " << w << "\n";
    {
      ProgressBar bar("bake " + input.filename().string(), progress);
      if (o.method == "histogram") r = bake_histogram(scene, cov, hist, bar.callback());
      else r = bake_raytraced(ray_scene(), cov, rt, bar.callback());
      bake_ms = clock.lap_ms();
    }
    timings["bake_ms"] = bake_ms;
    map_out = batch_path(input, o.output, o.out_dir, batch, "-ao.png");
    double sum = 0;
    for (std::size_t i = 0; i < r.mask.size(); ++i)
      if (r.mask[i]) sum += r.visibility[i];
    summary["output"] = map_out.string();
    summary["size"] = o.size;
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
      summary["parameters"] = rt;
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
      if (o.method == "histogram") {
        vertex_ao = bake_vertices_histogram(
            scene, {.directions = hist.directions, .direction_set = hist.direction_set, .resolution = o.vertex_resolution, .seed = o.seed}, bar.callback());
      } else {
        vertex_ao = bake_vertices_raytraced(ray_scene(), rt, &nrays, bar.callback());
      }
    }
    vertex_ms = clock.lap_ms();
    timings["per_vertex_ms"] = vertex_ms;
    if (nrays) summary["per_vertex_rays"] = nrays;
  }

  // Writes (each atomic).
  if (want_map) {
    write_image(map_out, r.visibility, {.png_bits = o.png_bits});
    if (!o.bent.empty() && !r.bent_normal.empty()) {
      Image<Vec3> enc(o.size, o.size, Vec3{0.5f, 0.5f, 0.5f});
      for (std::size_t i = 0; i < enc.size(); ++i)
        if (length(r.bent_normal[i]) > 0) enc[i] = r.bent_normal[i] * 0.5f + Vec3{0.5f, 0.5f, 0.5f};
      write_rgb_image(batch_path(input, o.bent, o.out_dir, batch, "-bent.png"), enc, {.png_bits = o.png_bits});
    }
    if (!o.gltf.empty()) {
      std::string png;
      if (map_out.extension() == ".png" || map_out.extension() == ".PNG") {
        png = read_bytes(map_out);
      } else {
        const fs::path tmp = fs::temp_directory_path() / ("ao-bake-" + std::to_string(::getpid()) + ".png");
        write_image(tmp, r.visibility, {.png_bits = 8});
        png = read_bytes(tmp);
        fs::remove(tmp);
      }
      const fs::path glb = batch_path(input, o.gltf, o.out_dir, batch, "-ao.glb");
      write_ao_glb(glb, scene, png, source ? &*source : nullptr);
      summary["gltf_output"] = glb.string();
    }
    if (!o.json)
      std::fprintf(stderr, "wrote %s: %s, %s, %dx%d, %zu texels covered, mean V = %.4f, %.0f ms (%.2f M texels/s)\n", map_out.string().c_str(),
                   input.filename().string().c_str(), o.method.c_str(), o.size, o.size, r.covered_texels, summary["mean_visibility"].get<double>(), bake_ms,
                   summary["texels_per_second"].get<double>() / 1e6);
  }
  if (!o.per_vertex.empty()) {
    const fs::path out = batch_path(input, o.per_vertex, o.out_dir, batch, "-ao.ply");
    write_vertex_ao_ply(out, scene, vertex_ao);
    summary["per_vertex_output"] = out.string();
    if (!o.json) std::fprintf(stderr, "wrote %s: %zu vertices, %.0f ms\n", out.string().c_str(), vertex_ao.size(), vertex_ms);
  }
  timings["write_ms"] = clock.lap_ms();
  summary["timings"] = timings;
  return summary;
}

int run_bake(BakeOptions o, const GlobalOptions& global) {
  if (o.method != "histogram" && o.method != "raytraced") throw InputError("--method: expected histogram or raytraced, got '" + o.method + "'");
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
  o.hist.validate();
  if (o.size < 1 || o.size > 16384) throw InputError("--size must be in [1, 16384]");
  const std::vector<fs::path> inputs = expand_inputs(o.inputs);
  if (inputs.empty()) throw InputError("no mesh files to bake (folders are searched for .obj .ply .off .stl .gltf .glb)");
  const bool batch = inputs.size() > 1 || fs::is_directory(o.inputs.front());
  check_output_names(o, batch);
  if (!batch) {
    const nlohmann::json s = bake_one(inputs.front(), o, false, global);
    if (o.json) std::cout << s.dump(2) << "\n";
    return 0;
  }
  nlohmann::json all = nlohmann::json::array();
  int failed = 0;
  for (const fs::path& in : inputs) {
    try {
      all.push_back(bake_one(in, o, true, global));
    } catch (const InputError& e) {
      ++failed;
      std::fprintf(stderr, "ao: error: %s\n", e.what());
      all.push_back({{"input", in.string()}, {"error", e.what()}});
    } catch (const SystemError& e) {
      ++failed;
      std::fprintf(stderr, "ao: error: %s\n", e.what());
      all.push_back({{"input", in.string()}, {"error", e.what()}});
    }
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
  cmd->add_option("-o,--output", o->output, "AO map: .png (linear, 8/16 bit) or .exr (float). Default <mesh>-ao.png; in a batch, <mesh>-<name>");
  cmd->add_option("--out-dir", o->out_dir, "Folder for the outputs of a batch (default: beside each mesh)");
  cmd->add_option("-m,--method", o->method, "histogram (outside-in, McGraw & Sowers; unlimited distance) or raytraced (Embree)")->capture_default_str();
  cmd->add_option("-s,--size", o->size, "Map width = height, texels [1, 16384]")->capture_default_str();
  cmd->add_option("--uv-set", o->uv_set, "UV set to bake into, from 0 (glTF TEXCOORD_n); the .glb of --gltf writes it as TEXCOORD_0")->capture_default_str();
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
  cmd->add_option("--max-distance", o->max_distance, "raytraced: occluders count only within this distance R, world units (default: unlimited)");
  cmd->add_option("--membership", o->membership, "raytraced with --max-distance: falloff step, linear, sqrt or cubic")->capture_default_str();
  cmd->add_option("--offset", o->rt.offset, "raytraced: ray origin offset along the face normal, world units (0: scale-free, a few float spacings of the coordinates; docs/methods/raytraced.md)")->capture_default_str();
  cmd->add_flag("--ignore-back-faces", o->rt.ignore_back_faces, "raytraced: rays pass through back faces (xNormal/Substance 'ignore backface')");
  cmd->add_option("--padding", o->padding, "Fill texels up to this far outside the charts from the nearest chart texel [0, 1024]")->capture_default_str();
  cmd->add_option("--png-bits", o->png_bits, "PNG bit depth, 8 or 16")->capture_default_str();
  cmd->add_option("--bent-normals", o->bent, "Also write the bent normals (average open direction, world space, n*0.5+0.5) to this image");
  cmd->add_option("--per-vertex", o->per_vertex, "Also (or, without -o/--gltf, only) write per-vertex AO to this PLY (colour + float quality)");
  cmd->add_option("--vertex-resolution", o->vertex_resolution, "histogram --per-vertex: view size in pixels [64, 8192]")->capture_default_str();
  cmd->add_option("--gltf", o->gltf, "Also write a .glb of the mesh with the map as its material's occlusion texture");
  cmd->add_option("--reference", o->reference, "Compare the map with this reference map (EXR/PNG, same size) over covered texels; RMSE etc. in --json");
  cmd->add_option("--seed", o->seed, "Seed of directions / sample sets")->capture_default_str();
  cmd->add_flag("--json", o->json, "Print a JSON summary (texels covered, directions or rays, timings, texels/s, rays/s) on stdout");
  cmd->callback([o, &global, &action] { action = [o, &global] { return run_bake(*o, global); }; });
}

}  // namespace ao::cli
