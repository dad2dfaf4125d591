// SPDX-License-Identifier: Apache-2.0
// The bake job's glTF round trip: a glTF/GLB input baked to a .glb (the gltf output, or a
// per-vertex .glb) keeps its document (gltf_document.h). Each glTF mesh with the UV set is baked
// once, into a map of its own, at its first instance with every other instance and mesh occluding;
// per-vertex AO becomes each primitive's COLOR_0.

#include <cstdio>
#include <string>
#include <vector>

#include "ao/bake/padding.h"
#include "ao/bake/udim.h"
#include "ao/core/error.h"
#include "ao/core/memory.h"
#include "ao/core/stopwatch.h"
#include "ao/io/atomic_file.h"
#include "ao/io/gltf_document.h"
#include "ao/io/gltf_export.h"
#include "ao/io/image_io.h"
#include "ao/jobs/bake_internal.h"
#include "ao/jobs/fields.h"
#include "ao/jobs/provenance.h"

namespace ao::bake_job {

namespace {

// The options that do not apply to a document kept as it is.
void check_round_trip_options(const Plan& plan, const fs::path& input) {
  const BakeRequest& r = plan.r;
  const std::pair<bool, std::string> unsupported[] = {
      {plan.high_to_low(), field(fields::kBakeHigh)},
      {!r.groups.empty() || r.self_occlusion || r.match_by_name, "bake groups"},
      {!r.outputs.bent_normals.empty(), field(fields::kBakeBentNormals)},
      {!r.outputs.thickness.empty(), field(fields::kBakeThickness)},
      {!r.outputs.cavity.empty(), field(fields::kBakeCavity)},
      {!r.orm.empty(), field(fields::kBakeOrm)},
      {!r.reference.empty(), field(fields::kBakeReference)},
      {!r.outputs.per_vertex.empty() && lower_extension(r.outputs.per_vertex) != ".glb", field(fields::kBakePerVertex) + " .ply"},
      {is_udim_pattern(r.outputs.map), "UDIM tiles"}};
  for (const auto& [given, what] : unsupported)
    if (given)
      throw InputError(input.string() + ": a glTF input baked to a .glb keeps its document, one map per glTF mesh; " + what + " does not apply to it (bake without " +
                       field(fields::kBakeGltf) + "/" + field(fields::kBakePerVertex) + " .glb for the flattened scene)");
}

// What one round trip carries between its steps.
struct RoundTrip {
  const Plan& plan;
  const fs::path& input;
  const MeshOutputs& outs;
  OutputSet& outputs;
  const JobReporter& reporter;
  GltfDocument doc;
  std::optional<std::vector<Mesh>> occluders;  ///< The same for every world scene (same bounds).
  nlohmann::json summary;
  nlohmann::json timings;
  Stopwatch clock;
  /// Lines for people ("baked ...", "wrote ..."), told once the outputs are committed: a run that
  /// fails later (another mesh, a write) says only its error.
  std::vector<std::string> notes;

  void add_occluders(GltfWorldScene& ws) {
    check_traceable_size(ws.scene);  // every world scene of the round trip passes here
    for (const std::string& w : ws.scene.warnings) reporter.warn(input.string() + ": " + w);
    if (!occluders) occluders = load_occluders(plan, ws.scene, nullptr, reporter);
    for (const Mesh& m : *occluders) ws.scene.meshes.push_back(m);
  }
  void save(const fs::path& path) {
    outputs.write(path, [&] {
      for (const std::string& w : doc.save_glb(path)) reporter.warn(input.string() + ": " + w);
    });
  }
};

void bake_round_trip_vertices(RoundTrip& job) {
  GltfWorldScene ws = job.doc.world_scene(-1);
  job.add_occluders(ws);
  std::uint64_t rays = 0;
  const std::vector<float> v = bake_vertices_of(job.plan, ws.scene, &rays, job.reporter.start("per-vertex " + job.input.filename().string()));
  std::size_t first = 0, vertices = 0;
  for (std::size_t i = 0; i < ws.sources.size(); ++i) {
    const std::size_t n = ws.scene.meshes[i].positions.size();
    if (ws.sources[i].first_instance) {
      job.doc.set_vertex_ao(ws.sources[i].mesh, ws.sources[i].primitive,
                            std::vector<float>(v.begin() + static_cast<std::ptrdiff_t>(first), v.begin() + static_cast<std::ptrdiff_t>(first + n)));
      vertices += n;
    }
    first += n;
  }
  job.timings["per_vertex_ms"] = job.clock.lap_ms();
  if (rays) job.summary["per_vertex_rays"] = rays;
  job.summary["per_vertex_vertices"] = vertices;
  job.save(job.outs.per_vertex);
  job.summary["per_vertex_output"] = job.outs.per_vertex.string();
  job.notes.push_back("wrote " + job.outs.per_vertex.string() + ": " + job.input.string() + ", per-vertex AO (COLOR_0) of " + std::to_string(vertices) +
                    " vertices");
}

// One map per target mesh, embedded in the document (and written to the map output when there is one).
void bake_round_trip_maps(RoundTrip& job, const std::vector<int>& targets, const fs::path& map) {
  const Plan& plan = job.plan;
  const std::string in = job.input.string();
  nlohmann::json maps = nlohmann::json::array();
  std::size_t covered = 0;
  for (int t : targets) {
    GltfWorldScene ws = job.doc.world_scene(t);
    job.add_occluders(ws);
    const std::string label = job.doc.mesh_label(t);
    const TexelCoverage cov = compute_texel_coverage(ws.scene, plan.width, plan.height);
    for (const std::string& w : cov.warnings()) job.reporter.warn(in + ": mesh " + label + ": " + w);
    BakeResult r = bake_map_plain(plan, ws.scene, cov, job.reporter.start("bake " + job.input.filename().string() + " " + label));
    const double mean = covered_mean(r);
    if (plan.r.padding > 0) pad(r.visibility, nearest_valid_texel(r.mask, plan.r.padding));
    // The map as PNG bytes (8 or 16 bit: glTF allows both), encoded in memory: no file to read back.
    job.doc.add_occlusion_map(t, encode_png(r.visibility, {.png_bits = plan.png_bits}));
    if (!map.empty()) {
      job.outputs.write(map, [&] { write_image(map, r.visibility, {.png_bits = plan.png_bits}); });
      job.notes.push_back("wrote " + map.string() + ": the map of mesh " + label);
    }
    maps.push_back({{"mesh", t}, {"name", label}, {"instances", job.doc.instance_count(t)}, {"texels_covered", r.covered_texels},
                    {"mean_visibility", mean}, {"rays", r.rays}, {"warnings", r.warnings}});
    covered += r.covered_texels;
    char line[512];
    std::snprintf(line, sizeof line, "baked %s mesh %s (%d instance%s): %dx%d, %zu texels covered, mean V = %.4f", in.c_str(), label.c_str(),
                  job.doc.instance_count(t), job.doc.instance_count(t) == 1 ? "" : "s", plan.width, plan.height, r.covered_texels, mean);
    job.notes.emplace_back(line);
  }
  job.timings["bake_ms"] = job.clock.lap_ms();
  job.summary["maps"] = maps;
  job.summary["width"] = plan.width;
  job.summary["height"] = plan.height;
  job.summary["texels_covered"] = covered;
  if (!map.empty()) job.summary["output"] = map.string();
}

}  // namespace

bool is_gltf_round_trip(const fs::path& input, const Plan& plan) {
  return (!plan.r.outputs.gltf.empty() || lower_extension(plan.r.outputs.per_vertex) == ".glb") && is_gltf_file(input);
}

MeshBake bake_gltf_input(const Plan& plan, const fs::path& input, const MeshOutputs& outs, OutputSet& outputs, const JobReporter& reporter) {
  check_round_trip_options(plan, input);
  const nlohmann::json record = plan.r.outputs.provenance ? bake_record(plan, input) : nlohmann::json();  // before the file is read
  RoundTrip job{plan, input, outs, outputs, reporter, GltfDocument(input, plan.r.uv_set)};
  const std::string in = input.string();
  for (const std::string& w : job.doc.warnings()) reporter.warn(in + ": " + w);
  const fs::path map = plan.writes_map_file() && !plan.r.outputs.map.empty() ? outs.map : fs::path();
  const bool want_map = !outs.gltf.empty() || !map.empty();
  const std::vector<int> targets = want_map ? job.doc.instanced_meshes(true) : std::vector<int>{};
  if (want_map && targets.empty())
    throw InputError(in + ": no mesh of the scene has UV set " + std::to_string(plan.r.uv_set) + " (TEXCOORD_" + std::to_string(plan.r.uv_set) +
                     "), so it cannot be baked to a texture; use " + field(fields::kBakePerVertex) + " out.glb for per-vertex AO");
  if (!map.empty() && targets.size() > 1)
    throw InputError(map.string() + ": " + field(fields::kBakeMap) + " names one map, but " + in + " bakes " + std::to_string(targets.size()) +
                     " meshes, each into its own map (embedded in the " + field(fields::kBakeGltf) + " output); drop " + field(fields::kBakeMap));
  check_memory(estimate_ray_scene_memory(job.doc.world_triangle_count(), job.doc.world_vertex_count()),
               in + ": the BVH of every instance, " + std::to_string(job.doc.world_triangle_count()) + " triangles");
  job.timings["load_ms"] = job.clock.lap_ms();
  job.summary = {{"ao", build_info()}, {"input", in}, {"gltf_round_trip", true}, {"world_triangles", job.doc.world_triangle_count()}};
  if (!outs.per_vertex.empty()) bake_round_trip_vertices(job);
  if (want_map) {
    bake_round_trip_maps(job, targets, map);
    if (!outs.gltf.empty()) {
      job.save(outs.gltf);
      job.summary["gltf_output"] = outs.gltf.string();
      job.notes.push_back("wrote " + outs.gltf.string() + ": " + in + " with " + std::to_string(targets.size()) + " AO map" + (targets.size() == 1 ? "" : "s"));
    }
  }
  job.timings["write_ms"] = job.clock.lap_ms();
  job.summary["timings"] = job.timings;
  job.summary["method"] = to_string(plan.r.method);
  if (plan.r.outputs.provenance) stage_provenance(outputs, record);
  outputs.commit();
  for (const std::string& line : job.notes) reporter.tell(line);
  MeshBake out;
  out.input = input;
  out.summary = std::move(job.summary);
  return out;
}

}  // namespace ao::bake_job
