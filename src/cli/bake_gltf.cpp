// ao bake's glTF round trip (bake_gltf.h): load the document, bake, add to it, save it as GLB.
#include "bake_gltf.h"

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>

#include "ao/bake/padding.h"
#include "ao/core/error.h"
#include "ao/core/memory.h"
#include "ao/io/atomic_file.h"
#include "ao/io/gltf_document.h"
#include "ao/io/image_io.h"
#include "common.h"

namespace ao::cli {

namespace {

namespace fs = std::filesystem;

std::string read_all(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

/// The map as PNG bytes (8 or 16 bit: glTF allows both), through a scratch file of write_image.
std::string encode_png(const Image<float>& map, int bits) {
  const ScratchFile tmp(fs::temp_directory_path() / ("ao-bake-" + std::to_string(::getpid()) + ".png"));
  write_image(tmp.path(), map, {.png_bits = bits});
  return read_all(tmp.path());
}

void append(Scene& scene, const std::vector<Mesh>& extra) {
  for (const Mesh& m : extra) scene.meshes.push_back(m);
}

}  // namespace

nlohmann::json bake_gltf_round_trip(const GltfRoundTrip& job, OutputSet& outputs) {
  Stopwatch clock;
  nlohmann::json timings;
  const std::string in = job.input.string();
  GltfDocument doc(job.input, job.uv_set);
  for (const std::string& w : doc.warnings()) std::cerr << "warning: " << in << ": " << w << "\n";
  const bool want_map = !job.gltf.empty() || !job.map.empty();
  const std::vector<int> targets = want_map ? doc.instanced_meshes(true) : std::vector<int>{};
  if (want_map && targets.empty())
    throw InputError(in + ": no mesh of the scene has UV set " + std::to_string(job.uv_set) + " (TEXCOORD_" + std::to_string(job.uv_set) +
                     "), so it cannot be baked to a texture; use --per-vertex out.glb for per-vertex AO");
  if (!job.map.empty() && targets.size() > 1)
    throw InputError(job.map.string() + ": -o names one map, but " + in + " bakes " + std::to_string(targets.size()) +
                     " meshes, each into its own map (embedded in the --gltf output); drop -o");
  check_memory(estimate_ray_scene_memory(doc.world_triangle_count(), doc.world_vertex_count()),
               in + ": the BVH of every instance, " + std::to_string(doc.world_triangle_count()) + " triangles");
  timings["load_ms"] = clock.lap_ms();

  nlohmann::json summary = {{"input", in}, {"gltf_round_trip", true}, {"world_triangles", doc.world_triangle_count()}};
  std::optional<std::vector<Mesh>> occluders;  // the same for every world scene (same bounds)
  auto with_occluders = [&](GltfWorldScene& ws) {
    for (const std::string& w : ws.scene.warnings) std::cerr << "warning: " << in << ": " << w << "\n";
    if (!occluders) occluders = job.occluders(ws.scene);
    append(ws.scene, *occluders);
  };

  if (!job.per_vertex.empty()) {
    GltfWorldScene ws = doc.world_scene(-1);
    with_occluders(ws);
    std::uint64_t rays = 0;
    const std::vector<float> v = job.bake_vertices(ws.scene, &rays);
    std::size_t first = 0, vertices = 0;
    for (std::size_t i = 0; i < ws.sources.size(); ++i) {
      const std::size_t n = ws.scene.meshes[i].positions.size();
      if (ws.sources[i].first_instance) {
        doc.set_vertex_ao(ws.sources[i].mesh, ws.sources[i].primitive, std::vector<float>(v.begin() + static_cast<std::ptrdiff_t>(first), v.begin() + static_cast<std::ptrdiff_t>(first + n)));
        vertices += n;
      }
      first += n;
    }
    timings["per_vertex_ms"] = clock.lap_ms();
    if (rays) summary["per_vertex_rays"] = rays;
    summary["per_vertex_vertices"] = vertices;
    outputs.write(job.per_vertex, [&] {
      for (const std::string& w : doc.save_glb(job.per_vertex)) std::cerr << "warning: " << in << ": " << w << "\n";
    });
    summary["per_vertex_output"] = job.per_vertex.string();
    if (!job.json) std::fprintf(stderr, "wrote %s: %s, per-vertex AO (COLOR_0) of %zu vertices\n", job.per_vertex.string().c_str(), in.c_str(), vertices);
  }

  if (want_map) {
    nlohmann::json maps = nlohmann::json::array();
    std::size_t covered = 0;
    for (int t : targets) {
      GltfWorldScene ws = doc.world_scene(t);
      with_occluders(ws);
      BakeResult r = job.bake_map(ws.scene, doc.mesh_label(t));
      double sum = 0;
      for (std::size_t i = 0; i < r.mask.size(); ++i)
        if (r.mask[i]) sum += r.visibility[i];
      if (job.padding > 0) pad(r.visibility, nearest_valid_texel(r.mask, job.padding));
      doc.add_occlusion_map(t, encode_png(r.visibility, job.png_bits));
      if (!job.map.empty()) {
        outputs.write(job.map, [&] { write_image(job.map, r.visibility, {.png_bits = job.png_bits}); });
        if (!job.json) std::fprintf(stderr, "wrote %s: the map of mesh %s\n", job.map.string().c_str(), doc.mesh_label(t).c_str());
      }
      const double mean = r.covered_texels ? sum / static_cast<double>(r.covered_texels) : 1.0;
      maps.push_back({{"mesh", t}, {"name", doc.mesh_label(t)}, {"instances", doc.instance_count(t)}, {"texels_covered", r.covered_texels},
                      {"mean_visibility", mean}, {"rays", r.rays}, {"warnings", r.warnings}});
      covered += r.covered_texels;
      if (!job.json)
        std::fprintf(stderr, "baked %s mesh %s (%d instance%s): %dx%d, %zu texels covered, mean V = %.4f\n", in.c_str(), doc.mesh_label(t).c_str(),
                     doc.instance_count(t), doc.instance_count(t) == 1 ? "" : "s", job.width, job.height, r.covered_texels, mean);
    }
    timings["bake_ms"] = clock.lap_ms();
    summary["maps"] = maps;
    summary["width"] = job.width;
    summary["height"] = job.height;
    summary["texels_covered"] = covered;
    if (!job.map.empty()) summary["output"] = job.map.string();
    if (!job.gltf.empty()) {
      outputs.write(job.gltf, [&] {
        for (const std::string& w : doc.save_glb(job.gltf)) std::cerr << "warning: " << in << ": " << w << "\n";
      });
      summary["gltf_output"] = job.gltf.string();
      if (!job.json) std::fprintf(stderr, "wrote %s: %s with %zu AO map%s\n", job.gltf.string().c_str(), in.c_str(), targets.size(), targets.size() == 1 ? "" : "s");
    }
  }
  timings["write_ms"] = clock.lap_ms();
  summary["timings"] = timings;
  return summary;
}

}  // namespace ao::cli
