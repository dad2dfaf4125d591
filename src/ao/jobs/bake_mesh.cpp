// SPDX-License-Identifier: Apache-2.0
// One mesh of the bake job: loaded, its map baked (plainly, group by group, high to low, or per
// UDIM tile), its per-vertex AO baked, and every output written at the end as one transaction, so
// a mesh that fails half-way leaves no partial set of outputs behind.
#include <algorithm>
#include <cstdio>


#include "ao/bake/bake_groups.h"
#include "ao/bake/padding.h"
#include "ao/bake/tangents.h"
#include "ao/bake/per_vertex.h"
#include "ao/bake/udim.h"
#include "ao/core/error.h"
#include "ao/core/memory.h"
#include "ao/core/params.h"
#include "ao/core/stopwatch.h"
#include "ao/eval/metrics.h"
#include "ao/io/atomic_file.h"
#include "ao/io/gltf_export.h"
#include "ao/io/image_io.h"
#include "ao/io/ply_export.h"
#include "ao/jobs/bake_internal.h"
#include "ao/jobs/fields.h"
#include "ao/jobs/provenance.h"
#include "ao/reference/ray_scene.h"

namespace ao::bake_job {

namespace {

// What one mesh's bake has loaded and made, passed between its steps.
struct MeshJob {
  const Plan& plan;
  fs::path input;
  const JobReporter& reporter;
  const Scene& scene;
  std::optional<Scene> high;
  std::vector<Mesh> occluders;
  nlohmann::json summary;
  nlohmann::json timings;
  Stopwatch clock;
  std::unique_ptr<RayScene> rays;  ///< Of the scene alone, built once for the map and per-vertex AO.
  /// The ray-traced settings with a relative distance resolved for the whole scene (so that
  /// every group, tile and map of the family takes the same R).
  RaytracedBakeParams ao;
  Image<float> thickness, cavity;  ///< The AO family's maps, padded; empty unless asked for.
  std::optional<float> fitted_extrusion;  ///< High to low: the cage distance fitted for job.scene, reused by the family's maps.
  nlohmann::json record;           ///< The provenance record of the outputs, when asked for (inputs hashed before loading).

  const Scene* high_scene() const { return high ? &*high : nullptr; }
  std::string label() const { return input.filename().string(); }
  RayScene& ray_scene() {
    if (!rays) {
      check_memory(estimate_ray_scene_memory(scene.triangle_count(), scene.vertex_count()),
                   input.string() + ": the BVH of " + std::to_string(scene.triangle_count()) + " triangles");
      rays = std::make_unique<RayScene>(scene, bake_bvh_options(scene.triangle_count()));
      timings["bvh_ms"] = clock.lap_ms();
    }
    return *rays;
  }
};

// The high meshes (BakeRequest::high, or the caller's high_scene), one scene (their UVs are not used).
Scene load_high_scene(const BakeRequest& r, const JobReporter& reporter) {
  if (r.high_scene) return *r.high_scene;
  const std::vector<fs::path>& files = r.high;
  Scene high;
  high.name = files.size() == 1 ? files.front().string() : "the high meshes";
  for (const fs::path& f : files) {
    Scene s = load_scene_file(f, kBakeLoad);
    for (const std::string& w : s.warnings) reporter.warn(w);  // the loader names the file
    for (Mesh& m : s.meshes) high.meshes.push_back(std::move(m));
  }
  return high;
}

// Bake groups: by name, explicit lists, one per mesh, or everything in one.
std::vector<BakeGroup> make_groups(const MeshJob& job, const Scene& scene) {
  const BakeRequest& r = job.plan.r;
  std::vector<BakeGroup> groups;
  if (r.match_by_name) {
    std::vector<std::string> unused;
    groups = groups_by_name(scene, *job.high, &unused);
    for (const std::string& n : unused) job.reporter.warn(field(fields::kBakeMatchByName) + ": high mesh '" + n + "' matches no low mesh and is not used");
    return groups;
  }
  if (!r.groups.empty()) {
    groups = groups_from_lists(scene, r.groups);
  } else if (r.self_occlusion) {
    groups = groups_per_mesh(scene);
  } else {
    BakeGroup all{"", {}, {}};
    for (std::size_t i = 0; i < scene.meshes.size(); ++i) all.meshes.push_back(i);
    groups.push_back(std::move(all));
  }
  if (job.high)
    for (BakeGroup& g : groups)
      for (std::size_t i = 0; i < job.high->meshes.size(); ++i) g.high.push_back(i);
  return groups;
}

// One group's map, high to low: AO at the group's high meshes, occluded by them and the occluders.
BakeResult bake_group_high_to_low(const MeshJob& job, const Scene& group_scene, const TexelCoverage& cov, const BakeGroup& g,
                                  const CagePositions& cage, const HighToLowParams& p, const ProgressFn& progress) {
  Scene targets;
  targets.name = job.high->name;
  for (std::size_t i : g.high) targets.meshes.push_back(job.high->meshes[i]);
  Scene blockers = targets;
  for (const Mesh& m : job.occluders) blockers.meshes.push_back(m);
  CagePositions gc;
  for (std::size_t i : g.meshes) gc.push_back(cage[i]);
  // Cage rays want triangles (their hits are interpolated); AO rays take the bake's quad BVH.
  const RayScene target_rays(targets, high_to_low_target_bvh_options(targets.triangle_count()));
  const RayScene blocker_rays(blockers, bake_bvh_options(blockers.triangle_count()));
  return bake_high_to_low(group_scene, cov, gc, target_rays, blocker_rays, p, progress);
}

// Texels every cage ray missed: how many, and what the given options allow to change (an explicit
// cage excludes an extrusion; a ray's reach is its front and back distances).
void warn_missed(const MeshJob& job, const BakeResult& r, const HighToLowParams& p) {
  const BakeRequest& q = job.plan.r;
  const bool cage = !q.cage.empty() || q.cage_scene;
  std::string raise;
  if (cage) raise = "push " + field(fields::kBakeCage) + " further out, or raise " + field(fields::kBakeMaxFront) + " or " + field(fields::kBakeMaxBack);
  else raise = "raise " + field(fields::kBakeCageExtrusion) + " (" + (q.high_to_low.cage_extrusion ? "given" : "fitted") + ": " + float_text(*p.cage_extrusion) +
               ") or " + field(fields::kBakeMaxBack);
  if (p.max_back) raise += " (" + field(fields::kBakeMaxBack) + " given: " + float_text(*p.max_back) + ")";
  job.reporter.warn(job.input.string() + ": " + std::to_string(r.missed_texels) + " of " + std::to_string(r.covered_texels) +
                    " texels: every cage ray missed the high mesh; filled from their neighbours (" + raise +
                    (q.outputs.miss_mask.empty() ? "; " + field(fields::kBakeMissMask) + " shows where)" : std::string(")")));
}

// The map baked group by group: high to low, or the group's own meshes with the occluders.
// `coverage`: the scene's own, when computed already (bake_groups reuses it for a group of every mesh).
// `rt`: the ray-traced settings, when not the job's (a map of the AO family).
BakeResult bake_in_groups(MeshJob& job, const Scene& scene, const ProgressFn& progress, const TexelCoverage* coverage = nullptr,
                          const RaytracedBakeParams* rt = nullptr) {
  const Plan& plan = job.plan;
  const std::vector<BakeGroup> groups = make_groups(job, scene);
  CagePositions cage;  // of the whole low scene; each group takes its meshes' cages
  HighToLowParams p = plan.r.high_to_low;
  p.ao = rt ? *rt : job.ao;
  if (job.high) {
    if (plan.r.cage_scene) {
      cage = cage_from_mesh(scene, *plan.r.cage_scene);
    } else if (!plan.r.cage.empty()) {
      cage = cage_from_mesh(scene, load_scene_file(plan.r.cage, kBakeLoad));
    } else {
      if (!p.cage_extrusion && &scene == &job.scene && job.fitted_extrusion) p.cage_extrusion = job.fitted_extrusion;  // the family's maps
      if (!p.cage_extrusion) {  // fitted to the pair, so cage rays reach the high meshes from ~99% of the low surface
        const RayScene high_rays(*job.high, high_to_low_target_bvh_options(job.high->triangle_count()));
        p.cage_extrusion = fitted_cage_extrusion(scene, high_rays);
        if (&scene == &job.scene) job.fitted_extrusion = p.cage_extrusion;
      }
      cage = extrude_cage(scene, *p.cage_extrusion);
    }
  }
  BakeResult r = bake_groups(scene, groups, job.high ? std::vector<Mesh>{} : job.occluders, plan.width, plan.height,
                             [&](const Scene& gs, const TexelCoverage& cov, const BakeGroup& g) -> BakeResult {
                               if (!job.high) return bake_map_plain(plan, gs, cov, progress, &p.ao);
                               return bake_group_high_to_low(job, gs, cov, g, cage, p, progress);
                             },
                             coverage);
  if (rt) return r;  // a map of the family: the summary and the warnings are the AO map's
  if (groups.size() > 1) job.summary["groups"] = groups.size();
  if (!job.occluders.empty()) job.summary["occluder_meshes"] = job.occluders.size();
  if (job.high) {
    std::vector<std::string> high_files;
    for (const fs::path& f : plan.r.high) high_files.push_back(f.string());
    if (plan.r.high_scene) high_files.push_back(plan.r.high_scene->name);
    job.summary["high"] = high_files;
    job.summary["high_triangles"] = job.high->triangle_count();
    job.summary["missed_texels"] = r.missed_texels;
    job.summary["parameters"] = p;
    if (r.missed_texels > 0) warn_missed(job, r, p);
  }
  return r;
}

// UDIM: the map output names a pattern (<UDIM> or .1001.); each tile with triangles is a map of its own.
void bake_udim_tiles(MeshJob& job, const fs::path& pattern, OutputSet& outputs) {
  const Plan& plan = job.plan;
  const std::vector<UdimTile> tiles = udim_tiles(job.scene);
  for (const UdimTile& t : tiles)  // tile 1001 of "ao.1001.png" is the pattern itself, already declared
    if (udim_tile_path(pattern, t.number()) != pattern) outputs.add_output(udim_tile_path(pattern, t.number()), "tile " + std::to_string(t.number()) + " of " + field(fields::kBakeMap));
  nlohmann::json tile_summary = nlohmann::json::array();
  std::size_t covered = 0;
  for (const UdimTile& t : tiles) {
    const Scene ts = udim_tile_scene(job.scene, t);
    const ProgressFn progress = job.reporter.start("bake " + job.label() + " tile " + std::to_string(t.number()));
    BakeResult tr = plan.grouped() ? bake_in_groups(job, ts, progress)
                                   : bake_map_plain(plan, ts, compute_texel_coverage(ts, plan.width, plan.height), progress, &job.ao);
    if (tr.covered_texels == 0) continue;  // a tile without texels is not written
    if (plan.r.padding > 0) pad(tr.visibility, nearest_valid_texel(tr.mask, plan.r.padding));
    const double mean = covered_mean(tr);
    const fs::path path = udim_tile_path(pattern, t.number());
    outputs.write(path, [&] { write_image(path, tr.visibility, {.png_bits = plan.png_bits}); });
    covered += tr.covered_texels;
    tile_summary.push_back({{"tile", t.number()}, {"output", path.string()}, {"texels_covered", tr.covered_texels}, {"mean_visibility", mean}});
  }
  job.timings["bake_ms"] = job.clock.lap_ms();
  job.summary["udim_tiles"] = tile_summary;
  job.summary["width"] = plan.width;
  job.summary["height"] = plan.height;
  job.summary["texels_covered"] = covered;
}

// World-space bent normals of the covered texels of `cov` into the tangent space of the scene's
// UV layout (bake/tangents.h).
void into_tangent_space(const Scene& scene, const TexelCoverage& cov, Image<Vec3>& bent) {
  std::vector<std::vector<CornerTangent>> tangents;
  for (const Mesh& m : scene.meshes) tangents.push_back(m.uvs.empty() ? std::vector<CornerTangent>{} : mikktspace_tangents(m));
  const TexelFrames frames = texel_frames(scene, cov, tangents);
  for (std::size_t i = 0; i < bent.size(); ++i)
    if (cov.mask[i] && length(bent[i]) > 0) bent[i] = to_tangent_space(bent[i], frames.t[i], frames.n[i], frames.sign[i]);
}

// Thickness: the AO map's rays turned into the mesh, mu = min(d / R, 1), R a fraction of the scene's size.
RaytracedBakeParams thickness_settings(const MeshJob& job) {
  RaytracedBakeParams rt = job.plan.r.raytraced;
  rt.hemisphere = Hemisphere::Inside;
  rt.membership = Membership::Linear;
  rt.max_distance = job.plan.r.thickness_distance;
  rt.relative_distance = true;
  return rt.with_absolute_distance(baked_bounds(job.scene));
}

// Cavity: the AO map's bake within a short R, a fraction of the scene's size.
RaytracedBakeParams cavity_settings(const MeshJob& job) {
  RaytracedBakeParams rt = job.plan.r.raytraced;
  rt.max_distance = job.plan.r.cavity_distance;
  rt.relative_distance = true;
  return rt.with_absolute_distance(baked_bounds(job.scene));
}

// One map of the AO family: the AO map's bake (plain or by groups) with settings `rt`.
Image<float> bake_family_map(MeshJob& job, const TexelCoverage& cov, RaytracedBakeParams rt, const std::string& what) {
  rt.bent_normals = false;
  const ProgressFn progress = job.reporter.start(what + " " + job.label());
  BakeResult r = job.plan.grouped() ? bake_in_groups(job, job.scene, progress, &cov, &rt) : bake_raytraced(job.ray_scene(), cov, rt, progress);
  job.summary[what] = {{"mean", covered_mean(r)}, {"max_distance", *rt.max_distance}, {"rays", r.rays}};
  return std::move(r.visibility);
}

// The map of the whole scene, with its summary, padded.
BakeResult bake_map(MeshJob& job, const fs::path& map_out) {
  const Plan& plan = job.plan;
  const TexelCoverage cov = compute_texel_coverage(job.scene, plan.width, plan.height);
  job.timings["uv_coverage_ms"] = job.clock.lap_ms();
  for (const std::string& w : cov.warnings()) job.reporter.warn(job.input.string() + ": " + w);
  const ProgressFn progress = job.reporter.start("bake " + job.label());
  BakeResult r = plan.grouped() ? bake_in_groups(job, job.scene, progress, &cov)
                 : plan.r.method == Baker::Histogram ? bake_histogram(job.scene, cov, plan.r.histogram, progress)
                                                      : bake_raytraced(job.ray_scene(), cov, job.ao, progress);
  const double bake_ms = job.clock.lap_ms();
  job.timings["bake_ms"] = bake_ms;
  if (plan.r.bent_normal_space == BentNormalSpace::Tangent && !r.bent_normal.empty()) into_tangent_space(job.scene, cov, r.bent_normal);
  const BakeOutputs& o = plan.r.outputs;
  if (!o.thickness.empty()) job.thickness = bake_family_map(job, cov, thickness_settings(job), "thickness");
  if (!o.cavity.empty()) job.cavity = bake_family_map(job, cov, cavity_settings(job), "cavity");
  if (!o.thickness.empty() || !o.cavity.empty()) job.timings["family_ms"] = job.clock.lap_ms();
  nlohmann::json& s = job.summary;
  s["output"] = map_out.string();
  if (plan.width == plan.height) s["size"] = plan.width;
  s["width"] = plan.width;
  s["height"] = plan.height;
  s["texels_covered"] = r.covered_texels;
  s["mean_visibility"] = covered_mean(r);
  s["texels_per_second"] = bake_ms > 0 ? static_cast<double>(r.covered_texels) / (bake_ms / 1000.0) : 0.0;
  s["warnings"] = r.warnings;
  s["overlapping_texels"] = cov.overlapping_texels;
  s["degenerate_uv_triangles"] = cov.degenerate_uv_triangles;
  s["stats"] = r.stats;
  if (!plan.r.reference.empty())  // before padding: only covered texels are compared
    s["against_reference"] = compare_images(r.visibility, read_image(plan.r.reference), r.mask);
  if (plan.r.method == Baker::Histogram) {
    s["directions"] = r.directions;
    s["parameters"] = plan.r.histogram;
  } else {
    s["rays"] = r.rays;
    s["rays_per_second"] = bake_ms > 0 ? static_cast<double>(r.rays) / (bake_ms / 1000.0) : 0.0;
    if (!job.high) s["parameters"] = plan.r.raytraced;
  }
  if (plan.r.padding > 0) {
    const Image<std::int32_t> nearest = nearest_valid_texel(r.mask, plan.r.padding);
    pad(r.visibility, nearest);
    if (!r.bent_normal.empty()) pad(r.bent_normal, nearest);
    for (Image<float>* family : {&job.thickness, &job.cavity})
      if (!family->empty()) pad(*family, nearest);
  }
  job.timings["padding_ms"] = job.clock.lap_ms();
  return r;
}

// Per-vertex AO of the scene's vertices; with occluders they occlude too (the scene's meshes come
// first, so their vertices lead the result).
std::vector<float> bake_vertex_ao(MeshJob& job) {
  std::uint64_t nrays = 0;
  const ProgressFn progress = job.reporter.start("per-vertex " + job.label());
  std::vector<float> v;
  if (job.occluders.empty()) {
    v = job.plan.r.method == Baker::Histogram ? bake_vertices_of(job.plan, job.scene, &nrays, progress)
                                                : bake_vertices_raytraced(job.ray_scene(), job.ao, &nrays, progress);
  } else {
    Scene with_occluders = job.scene;
    for (const Mesh& m : job.occluders) with_occluders.meshes.push_back(m);
    v = bake_vertices_of(job.plan, with_occluders, &nrays, progress);
  }
  v.resize(job.scene.vertex_count());
  job.timings["per_vertex_ms"] = job.clock.lap_ms();
  if (nrays) job.summary["per_vertex_rays"] = nrays;
  return v;
}

// The map file, the miss mask, the bent normals and the glTF, staged in `outputs`.
void write_map_outputs(MeshJob& job, const BakeResult& r, const MeshOutputs& outs, const std::vector<float>& vertex_ao, OutputSet& outputs) {
  const Plan& plan = job.plan;
  const bool write_map = plan.writes_map_file();
  // The glTF embeds the map file's own bytes when the map is a PNG, else the map as a PNG of the
  // same bit depth (glTF allows 16-bit PNG); encoded in memory either way, so nothing is read back.
  std::string png;
  if (write_map && !plan.r.orm.empty()) {
    // The ORM texture with V in its red channel (glTF's occlusion channel); G, B, A and the depth as they were.
    StoredPng packed = read_stored_png(plan.r.orm);
    replace_channel(packed, 0, r.visibility);
    if (!outs.gltf.empty()) png = encode_stored_png(packed);
    outputs.write(outs.map, [&] { write_stored_png(outs.map, packed); });
  } else if (write_map) {
    outputs.write(outs.map, [&] { write_image(outs.map, r.visibility, {.png_bits = plan.png_bits}); });
  }
  if (!outs.miss.empty()) {
    Image<float> miss(plan.width, plan.height, 0.0f);
    for (std::size_t i = 0; i < r.missed.size(); ++i) miss[i] = r.missed[i];
    outputs.write(outs.miss, [&] { write_image(outs.miss, miss, {}); });
  }
  if (!outs.bent.empty() && !r.bent_normal.empty()) {
    Image<Vec3> enc(plan.width, plan.height, Vec3{0.5f, 0.5f, 0.5f});
    for (std::size_t i = 0; i < enc.size(); ++i)
      if (length(r.bent_normal[i]) > 0) enc[i] = r.bent_normal[i] * 0.5f + Vec3{0.5f, 0.5f, 0.5f};
    outputs.write(outs.bent, [&] { write_rgb_image(outs.bent, enc, {.png_bits = plan.png_bits}); });
  }
  if (!outs.thickness.empty()) outputs.write(outs.thickness, [&] { write_image(outs.thickness, job.thickness, {.png_bits = plan.png_bits}); });
  if (!outs.cavity.empty()) outputs.write(outs.cavity, [&] { write_image(outs.cavity, job.cavity, {.png_bits = plan.png_bits}); });
  if (!outs.gltf.empty()) {
    if (png.empty()) png = encode_png(r.visibility, {.png_bits = plan.png_bits});
    outputs.write(outs.gltf, [&] { write_ao_glb(outs.gltf, job.scene, png, vertex_ao.empty() ? nullptr : &vertex_ao); });
    job.summary["gltf_output"] = outs.gltf.string();
  }
}

void tell_written(const MeshJob& job, const MeshBake& out, const MeshOutputs& outs, bool udim) {
  const Plan& plan = job.plan;
  char line[512];
  if (udim)
    for (const auto& t : job.summary["udim_tiles"]) {
      std::snprintf(line, sizeof line, "wrote %s: %s, tile %d, %dx%d, %zu texels covered, mean V = %.4f", t["output"].get<std::string>().c_str(),
                    job.label().c_str(), t["tile"].get<int>(), plan.width, plan.height, t["texels_covered"].get<std::size_t>(),
                    t["mean_visibility"].get<double>());
      job.reporter.tell(line);
    }
  if (plan.wants_map() && plan.writes_map_file() && !udim) {
    std::snprintf(line, sizeof line, "wrote %s: %s, %s, %dx%d, %zu texels covered, mean V = %.4f, %.0f ms (%.2f M texels/s)", outs.map.string().c_str(),
                  job.label().c_str(), std::string(to_string(plan.r.method)).c_str(), plan.width, plan.height, out.map.covered_texels,
                  job.summary["mean_visibility"].get<double>(), job.timings["bake_ms"].get<double>(), job.summary["texels_per_second"].get<double>() / 1e6);
    job.reporter.tell(line);
  }
  for (const auto& [path, what] : {std::pair{outs.thickness, "thickness"}, std::pair{outs.cavity, "cavity"}})
    if (!path.empty() && job.summary.contains(what)) {
      std::snprintf(line, sizeof line, "wrote %s: %s of %s, R = %g, mean %.4f", path.string().c_str(), what, job.label().c_str(),
                    job.summary[what]["max_distance"].get<double>(), job.summary[what]["mean"].get<double>());
      job.reporter.tell(line);
    }
  if (!outs.per_vertex.empty()) {
    std::snprintf(line, sizeof line, "wrote %s: %zu vertices, %.0f ms", outs.per_vertex.string().c_str(), out.vertex_ao.size(),
                  job.timings.value("per_vertex_ms", 0.0));
    job.reporter.tell(line);
  }
}

// Everything computed first and written at the end: the map (plain, grouped or UDIM tiles) and
// per-vertex AO of `job.scene`, into `outputs` when given.
MeshBake bake_and_write(MeshJob& job, const MeshOutputs& outs, OutputSet* outputs) {
  const Plan& plan = job.plan;
  if (plan.wants_map() && !std::any_of(job.scene.meshes.begin(), job.scene.meshes.end(), [](const Mesh& m) { return !m.uvs.empty(); }))
    throw InputError(job.input.string() + ": the mesh has no UV coordinates, so it cannot be baked to a texture; use " + field(fields::kBakePerVertex) + " out.ply for per-vertex AO");
  MeshBake out;
  out.input = job.input;
  const bool udim = outputs && plan.wants_map() && plan.writes_map_file() && is_udim_pattern(outs.map);
  if (udim) bake_udim_tiles(job, outs.map, *outputs);
  else if (plan.wants_map()) out.map = bake_map(job, outs.map);
  if (!plan.r.outputs.per_vertex.empty()) out.vertex_ao = bake_vertex_ao(job);
  if (!plan.writes_map_file() || udim) job.summary.erase("output");  // UDIM tiles were written above
  if (outputs) {
    if (plan.wants_map() && !udim) write_map_outputs(job, out.map, outs, out.vertex_ao, *outputs);
    if (!outs.per_vertex.empty()) {
      outputs->write(outs.per_vertex, [&] {
        if (lower_extension(outs.per_vertex) == ".glb") write_ao_glb(outs.per_vertex, job.scene, "", &out.vertex_ao);
        else write_vertex_ao_ply(outs.per_vertex, job.scene, out.vertex_ao);
      });
      job.summary["per_vertex_output"] = outs.per_vertex.string();
    }
    if (plan.r.outputs.provenance) stage_provenance(*outputs, job.record);
    outputs->commit();
    tell_written(job, out, outs, udim);
  }
  job.timings["write_ms"] = job.clock.lap_ms();
  job.summary["timings"] = job.timings;
  out.thickness = std::move(job.thickness), out.cavity = std::move(job.cavity);  // written above from the job's
  out.summary = std::move(job.summary);
  return out;
}

}  // namespace

MeshBake bake_mesh(const Plan& plan, const fs::path& input, const JobReporter& reporter) {
  const MeshOutputs outs = outputs_of(input, plan);
  OutputSet outputs;
  declare(outputs, input, plan, outs);
  if (is_gltf_round_trip(input, plan)) return bake_gltf_input(plan, input, outs, outputs, reporter);
  Stopwatch clock;
  nlohmann::json record = plan.r.outputs.provenance ? bake_record(plan, input) : nlohmann::json();
  Scene scene = load_scene_file(input, {.uv_set = plan.r.uv_set, .flatten_instances = true});
  for (const std::string& w : scene.warnings) reporter.warn(w);  // the loader names the file
  check_traceable_size(scene);  // the histogram baker traces no ray: checked here for both
  MeshJob job{plan, input, reporter, scene};
  job.ao = plan.r.raytraced.with_absolute_distance(baked_bounds(scene));
  job.clock = clock;
  job.record = std::move(record);
  job.timings["load_ms"] = job.clock.lap_ms();
  job.summary = {{"ao", build_info()}, {"input", input.string()}, {"method", to_string(plan.r.method)}, {"triangles", scene.triangle_count()}, {"vertices", scene.vertex_count()}};
  if (plan.high_to_low()) job.high = load_high_scene(plan.r, reporter);
  job.occluders = load_occluders(plan, scene, job.high_scene(), reporter);
  return bake_and_write(job, outs, &outputs);
}

MeshBake bake_scene(const Plan& plan, const Scene& scene, const JobReporter& reporter) {
  check_traceable_size(scene);
  MeshJob job{plan, scene.name, reporter, scene};
  job.ao = plan.r.raytraced.with_absolute_distance(baked_bounds(scene));
  job.summary = {{"ao", build_info()}, {"input", scene.name}, {"method", to_string(plan.r.method)}, {"triangles", scene.triangle_count()}, {"vertices", scene.vertex_count()}};
  if (plan.high_to_low()) job.high = load_high_scene(plan.r, reporter);
  job.occluders = load_occluders(plan, scene, job.high_scene(), reporter);
  return bake_and_write(job, MeshOutputs{}, nullptr);
}

}  // namespace ao::bake_job
