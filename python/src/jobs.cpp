// SPDX-License-Identifier: Apache-2.0
// The jobs as Python calls: each fills the job layer's request (ao/jobs/) from a dict that
// ao/__init__.py builds from the keyword arguments, runs it through Call (GIL released, Ctrl-C,
// warnings), and hands the images back as numpy arrays that own them.
#include "jobs.h"

#include <algorithm>
#include <cstdlib>

#include "ao/core/closest_name.h"
#include "ao/core/error.h"
#include "ao/core/params_table.h"
#include "ao/io/mesh_io.h"
#include "ao/jobs/bake.h"
#include "ao/jobs/compare.h"
#include "ao/jobs/points.h"
#include "ao/jobs/render.h"
#include "ao/jobs/render_view.h"
#include "ao/reference/ray_scene.h"
#include "ao/registry/registry.h"
#include "call.h"
#include "convert.h"

namespace ao::python {

namespace {

nlohmann::json object_of(const nlohmann::json& request, const char* key) {
  const nlohmann::json v = request.value(key, nlohmann::json::object());
  if (!v.is_object()) throw py::type_error(std::string(key) + ": expected a dict");
  return v;
}

std::uint32_t seed_of(const nlohmann::json& request) {
  const nlohmann::json s = request.value("seed", nlohmann::json(1));
  if (!s.is_number_integer()) throw py::type_error("seed: expected an integer");
  if (s.get<std::int64_t>() < 0 || s.get<std::int64_t>() > 4294967295LL) throw InputError("seed: expected an integer in [0, 4294967295], got " + s.dump());
  return static_cast<std::uint32_t>(s.get<std::int64_t>());
}

std::filesystem::path path_of(const nlohmann::json& request, const char* key) {
  return std::filesystem::path(string_of(request, key, key).value_or(std::string()));
}

// The keyword parameters' names against the method's table, with the line `ao render -p` prints
// for a name the method lacks (values are checked by the job, as for the CLI).
void check_param_names(const std::string& method, const nlohmann::json& params) {
  const MethodInfo* info = nullptr;
  for (const MethodInfo& m : all_methods())
    if (m.name == method) info = &m;
  if (info == nullptr) return;  // run_render names the unknown method
  const nlohmann::json known = info->default_params();
  for (const auto& [key, value] : params.items()) {
    if (known.contains(key)) continue;
    std::string names;
    for (const auto& [k, v] : known.items()) names += (names.empty() ? "" : ", ") + k;
    throw InputError("method " + method + " has no parameter '" + key + "' (it has: " + names + ")" + did_you_mean(key, names));
  }
}

RenderRequest render_request(py::handle scene, py::handle gbuffer, const nlohmann::json& q) {
  RenderRequest r;
  if (!gbuffer.is_none()) r.gbuffer = gbuffer.cast<const GBufferHandle&>().gbuffer;
  else r.scene = scene_source(scene);
  r.method = string_of(q, "method", "method").value_or("raytraced");
  r.params = object_of(q, "params");
  check_param_names(r.method, r.params);
  r.samples = int_of(q, "samples", "spp");
  r.target_error = float_of(q, "target_error", "target_error");
  r.camera = camera_request(q, r.camera);
  r.falloff = falloff_request(q);
  if (const auto normal = string_of(q, "normal", "normal")) r.normal = surface_normal_from_name(*normal);
  r.seed = seed_of(q);
  r.outputs.visibility = path_of(q, "output");
  r.outputs.shaded = path_of(q, "shaded");
  r.outputs.gbuffer = path_of(q, "gbuffer_output");
  r.outputs.png_bits = int_of(q, "png_bits", "png_bits").value_or(8);
  r.outputs.extras = bool_of(q, "extras", "extras").value_or(false);
  r.outputs.provenance = bool_of(q, "provenance", "provenance").value_or(false);
  return r;
}

}  // namespace

py::dict render(py::handle scene, py::handle gbuffer, py::handle request, py::object progress) {
  const nlohmann::json q = to_json(request, "");
  const RenderRequest r = render_request(scene, gbuffer, q);
  Call call(std::move(progress));
  RenderResult out = call.run([&] { return run_render(r, call.reporter()); });
  py::dict d;
  d["visibility"] = to_array(std::move(out.output.visibility));
  if (!out.output.std_error.empty()) d["std_error"] = to_array(std::move(out.output.std_error));
  if (!out.output.color.empty()) d["color"] = to_array(std::move(out.output.color));
  py::dict extras;
  for (auto& [name, image] : out.output.extras) extras[py::str(name)] = to_array(std::move(image));
  d["extras"] = extras;
  d["summary"] = from_json(out.summary);
  if (bool_of(q, "return_gbuffer", "full").value_or(false)) d["gbuffer"] = GBufferHandle{std::make_shared<const GBuffer>(std::move(out.gbuffer))};
  return d;
}

py::dict render_record(py::handle scene, py::handle gbuffer, py::handle request) {
  const RenderRequest r = render_request(scene, gbuffer, to_json(request, ""));
  return from_json(render_provenance(r, /*hash_inputs=*/false));
}

GBufferHandle gbuffer(py::handle scene, py::handle request, py::object progress) {
  const nlohmann::json q = to_json(request, "");
  const SceneSource source = scene_source(scene);
  const CameraRequest camera = camera_request(q, CameraRequest{});
  const GBufferOptions options{.normal = surface_normal_from_name(string_of(q, "normal", "normal").value_or("shading")),
                               .albedo = bool_of(q, "albedo", "albedo").value_or(true), .uv = bool_of(q, "uv", "uv").value_or(false)};
  Call call(std::move(progress));
  return call.run([&] {
    const std::shared_ptr<const Scene> s = source.load();
    for (const std::string& w : s->warnings) call.reporter().warn(w);
    const PreparedScene prepared(s, "ao.gbuffer", BvhOptions{});
    const Camera cam = choose_camera(*s, camera);
    return GBufferHandle{std::make_shared<const GBuffer>(render_view_gbuffer(prepared, cam, options, std::nullopt, call.reporter()))};
  });
}

namespace {

// The baker's parameters (its table's names), with denoise a setting of the request.
void bake_params(BakeRequest& r, nlohmann::json params) {
  if (params.contains("denoise")) {
    r.denoise = float_of(params, "denoise", "denoise");
    params.erase("denoise");
  }
  if (r.method == Baker::Histogram) histogram_param_table().from_json(params, r.histogram);
  else raytraced_bake_param_table().from_json(params, r.raytraced);
}

// High to low: `high` (None, an ao.Scene or a list of mesh files), `cage` (None, an ao.Scene or a
// mesh file) and the cage's reach ("cage_extrusion", "max_front", "max_back", "cage_points").
void high_to_low_request(BakeRequest& r, const nlohmann::json& q, py::handle high, py::handle cage) {
  if (py::isinstance<SceneHandle>(high)) {
    r.high_scene = high.cast<const SceneHandle&>().scene;
  } else if (!high.is_none()) {
    const nlohmann::json files = to_json(high, "high");
    if (!files.is_array() || !std::all_of(files.begin(), files.end(), [](const nlohmann::json& f) { return f.is_string(); }))
      throw py::type_error("high: expected an ao.Scene or a list of mesh files");
    for (const nlohmann::json& f : files) r.high.emplace_back(f.get<std::string>());
  }
  if (py::isinstance<SceneHandle>(cage)) {
    r.cage_scene = cage.cast<const SceneHandle&>().scene;
  } else if (!cage.is_none()) {
    const nlohmann::json file = to_json(cage, "cage");
    if (!file.is_string()) throw py::type_error("cage: expected an ao.Scene or a mesh file");
    r.cage = file.get<std::string>();
  }
  HighToLowParams& h = r.high_to_low;
  h.cage_extrusion = float_of(q, "cage_extrusion", "cage_extrusion");
  h.max_front = float_of(q, "max_front", "max_front");
  h.max_back = float_of(q, "max_back", "max_back");
  h.cage_points = int_of(q, "cage_points", "cage_points").value_or(h.cage_points);
}

// `files`: set when the request names files to write (then a mesh file is baked by the job as
// `ao bake` bakes it, outputs included).
BakeRequest bake_request(py::handle mesh, const nlohmann::json& q, py::handle high, py::handle cage, bool& files) {
  BakeRequest r;
  r.method = baker_from_name(string_of(q, "method", "method").value_or("raytraced"));
  if (q.contains("size") && !q["size"].is_null()) {
    if (!q["size"].is_string() && !q["size"].is_number_integer()) throw py::type_error("size: expected an integer or a string 'WIDTHxHEIGHT'");
    r.size = parse_map_size(q["size"].is_string() ? q["size"].get<std::string>() : q["size"].dump());
  }
  r.uv_set = int_of(q, "uv_set", "uv_set").value_or(0);
  r.padding = int_of(q, "padding", "padding").value_or(r.padding);
  r.vertex_resolution = int_of(q, "vertex_resolution", "vertex_resolution").value_or(r.vertex_resolution);
  bake_params(r, object_of(q, "params"));
  high_to_low_request(r, q, high, cage);
  r.outputs.map = path_of(q, "output");
  r.outputs.per_vertex = path_of(q, "per_vertex_output");
  r.outputs.bent_normals = path_of(q, "bent_normals_output");
  r.outputs.thickness = path_of(q, "thickness_output");
  r.outputs.cavity = path_of(q, "cavity_output");
  r.outputs.gltf = path_of(q, "gltf_output");
  if (const auto space = string_of(q, "bent_normals_space", "bent_normals_space")) r.bent_normal_space = bent_normal_space_from_name(*space);
  r.thickness_distance = float_of(q, "thickness_distance", "thickness_distance").value_or(r.thickness_distance);
  r.cavity_distance = float_of(q, "cavity_distance", "cavity_distance").value_or(r.cavity_distance);
  r.outputs.png_bits = int_of(q, "png_bits", "png_bits");
  r.outputs.provenance = bool_of(q, "provenance", "provenance").value_or(false);
  files = !r.outputs.map.empty() || !r.outputs.per_vertex.empty() || !r.outputs.bent_normals.empty() || !r.outputs.thickness.empty() ||
          !r.outputs.cavity.empty() || !r.outputs.gltf.empty();
  if (py::isinstance<SceneHandle>(mesh)) {
    if (files) throw InputError("ao.bake: outputs are written for mesh files; bake a mesh made from arrays and save the arrays");
    r.scene = mesh.cast<const SceneHandle&>().scene;
  } else {
    const nlohmann::json path = to_json(mesh, "mesh");
    if (!path.is_string()) throw py::type_error("mesh: expected a mesh file or an ao.Scene");
    r.inputs = {path.get<std::string>()};
    if (std::filesystem::is_directory(r.inputs.front()))
      throw InputError(r.inputs.front().string() + ": ao.bake bakes one mesh; bake a folder with python3 -m ao.batch bake");
  }
  // Without files, what to compute: the job bakes a map unless only per-vertex AO is named, and
  // writes nothing for a mesh in memory (these names only say what to bake).
  if (!files) {
    if (bool_of(q, "map", "map").value_or(true)) r.outputs.map = "map.png";
    if (bool_of(q, "per_vertex", "per_vertex").value_or(false)) r.outputs.per_vertex = "per-vertex.ply";
    if (bool_of(q, "bent_normals", "bent_normals").value_or(false)) r.outputs.bent_normals = "bent.png";
    if (bool_of(q, "thickness", "thickness").value_or(false)) r.outputs.thickness = "thickness.png";
    if (bool_of(q, "cavity", "cavity").value_or(false)) r.outputs.cavity = "cavity.png";
    if (r.outputs.map.empty() && r.outputs.per_vertex.empty()) throw InputError("ao.bake: nothing to bake: ask for the map or per_vertex");
  }
  return r;
}

}  // namespace

py::dict bake_record(py::handle mesh, py::handle request, py::handle high, py::handle cage) {
  bool files = false;
  const BakeRequest r = bake_request(mesh, to_json(request, ""), high, cage, files);
  if (r.inputs.size() != 1) throw InputError("provenance: a record describes the outputs of one mesh file");
  return from_json(bake_provenance(r, r.inputs.front(), /*hash_inputs=*/false));
}

py::dict bake(py::handle mesh, py::handle request, py::object progress, py::handle high, py::handle cage) {
  const nlohmann::json q = to_json(request, "");
  bool files = false;
  BakeRequest r = bake_request(mesh, q, high, cage, files);
  Call call(std::move(progress));
  BakeBatchResult out = call.run([&] {
    // A mesh file baked without files to write is loaded as `ao bake` loads it and baked in memory.
    if (!r.scene && !files) {
      auto s = std::make_shared<Scene>(load_scene_file(r.inputs.front(), {.uv_set = r.uv_set, .flatten_instances = true}));
      for (const std::string& w : s->warnings) call.reporter().warn(w);
      r.scene = std::move(s);
      r.inputs.clear();
    }
    return run_bake(r, call.reporter());
  });
  MeshBake& m = out.meshes.front();
  if (!m.error.empty()) throw InputError(m.error);
  py::dict d;
  if (!m.map.visibility.empty()) {
    d["map"] = to_array(std::move(m.map.visibility));
    d["mask"] = to_array(std::move(m.map.mask));
  }
  if (!m.map.bent_normal.empty()) d["bent_normals"] = to_array(std::move(m.map.bent_normal));
  if (!m.thickness.empty()) d["thickness"] = to_array(std::move(m.thickness));
  if (!m.cavity.empty()) d["cavity"] = to_array(std::move(m.cavity));
  if (!m.vertex_ao.empty()) d["per_vertex"] = to_array(std::move(m.vertex_ao));
  d["summary"] = from_json(m.summary);
  return d;
}

py::dict occlusion(py::handle scene, py::handle points, py::handle normals, py::handle request, py::object progress) {
  const nlohmann::json q = to_json(request, "");
  PointsRequest r;
  r.scene = scene_source(scene);
  r.points = rows_of_vec3(points, "points");
  r.normals = rows_of_vec3(normals, "normals");
  r.falloff = falloff_request(q);
  raytraced_param_table().from_json(object_of(q, "params"), r.params);
  r.seed = seed_of(q);
  Call call(std::move(progress));
  PointsResult out = call.run([&] { return run_points(r, call.reporter()); });
  py::dict d;
  d["visibility"] = to_array(std::move(out.visibility));
  d["std_error"] = to_array(std::move(out.std_error));
  d["summary"] = from_json(out.summary);
  return d;
}

namespace {

CompareRequest compare_request(py::handle scene, const nlohmann::json& q) {
  CompareRequest r;
  r.scene = scene_source(scene);
  r.camera = camera_request(q, r.camera);
  r.falloff = falloff_request(q);
  r.normal = surface_normal_from_name(string_of(q, "normal", "normal").value_or("shading"));
  CompareSettings& s = r.settings;
  if (q.contains("methods") && !q["methods"].is_null()) {
    const nlohmann::json& m = q["methods"];
    if (!m.is_array() || !std::all_of(m.begin(), m.end(), [](const nlohmann::json& v) { return v.is_string(); }))
      throw py::type_error("methods: expected a list of method names");
    s.methods = m.get<std::vector<std::string>>();
  }
  // Each method's overrides over its defaults, as `ao compare -p method.key=value` sets them.
  const nlohmann::json per_method = object_of(q, "params");
  for (const auto& [name, overrides] : per_method.items()) {
    nlohmann::json p = find_method(name).default_params();
    if (!overrides.is_object()) throw py::type_error("params['" + name + "']: expected a dict of parameters");
    check_param_names(name, overrides);
    for (const auto& [k, v] : overrides.items()) p[k] = v;
    s.params[name] = p;
  }
  const nlohmann::json ref = q.value("reference", nlohmann::json());
  if (ref.is_string()) {
    s.references[""] = ref.get<std::string>();
  } else if (ref.is_object()) {
    for (const auto& [method, name] : ref.items()) {
      if (!name.is_string()) throw py::type_error("reference['" + method + "']: expected a reference name");
      s.references[method] = name.get<std::string>();
    }
  } else if (!ref.is_null()) {
    throw py::type_error("reference: expected a reference name or a dict {method: reference}");
  }
  s.common_reference = string_of(q, "common_reference", "common_reference").value_or(s.common_reference);
  s.spp_reference = int_of(q, "spp_reference", "spp_reference").value_or(s.spp_reference);
  s.seed = seed_of(q);
  const nlohmann::json sweep = q.value("sweep", nlohmann::json());
  if (sweep.is_object() && sweep.size() == 1 && sweep.begin().value().is_array()) {
    s.sweep_key = sweep.begin().key();
    s.sweep_values = sweep.begin().value().get<std::vector<nlohmann::json>>();
  } else if (!sweep.is_null()) {
    throw InputError("sweep: expected {key: [values]} for one parameter");
  }
  r.out_dir = path_of(q, "out_dir");
  // The sheet's font as `ao compare` finds it: $AO_FONT when set, else DejaVu Sans.
  if (const char* env = std::getenv("AO_FONT"); env != nullptr && *env != 0) r.font = env;
  return r;
}

}  // namespace

py::dict compare(py::handle scene, py::handle request, py::object progress) {
  const nlohmann::json q = to_json(request, "");
  const CompareRequest r = compare_request(scene, q);
  Call call(std::move(progress));
  CompareJobResult out = call.run([&] { return run_compare(r, call.reporter()); });
  py::dict d;
  d["table"] = from_json(out.table);
  d["markdown"] = out.markdown;
  if (bool_of(q, "images", "images").value_or(false)) {
    py::list images;
    for (CompareRow& row : out.result.rows) {
      py::dict i;
      i["method"] = row.method;
      i["visibility"] = to_array(std::move(row.visibility));
      i["reference"] = to_array(Image<float>(out.result.references[row.reference].visibility));
      images.append(i);
    }
    d["images"] = images;
  }
  return d;
}

}  // namespace ao::python
