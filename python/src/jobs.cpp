// The jobs as Python calls: each fills the job layer's request (ao/jobs/) from a dict that
// ao/__init__.py builds from the keyword arguments, runs it through Call (GIL released, Ctrl-C,
// warnings), and hands the images back as numpy arrays that own them.
#include "jobs.h"

#include <cstdlib>

#include "ao/core/error.h"
#include "ao/io/mesh_io.h"
#include "ao/jobs/bake.h"
#include "ao/jobs/compare.h"
#include "ao/jobs/render.h"
#include "ao/reference/ray_scene.h"
#include "ao/registry/registry.h"
#include "call.h"
#include "convert.h"

namespace ao::python {

namespace {

nlohmann::json object_of(const nlohmann::json& request, const char* key) {
  const nlohmann::json v = request.value(key, nlohmann::json::object());
  if (!v.is_object()) throw InputError(std::string(key) + ": expected a dict, got " + v.dump());
  return v;
}

std::uint32_t seed_of(const nlohmann::json& request) {
  const nlohmann::json s = request.value("seed", nlohmann::json(1));
  if (!s.is_number_integer() || s.get<std::int64_t>() < 0 || s.get<std::int64_t>() > 4294967295LL)
    throw InputError("--seed: expected an integer in [0, 4294967295], got " + s.dump());
  return static_cast<std::uint32_t>(s.get<std::int64_t>());
}

std::filesystem::path path_of(const nlohmann::json& request, const char* key) {
  const nlohmann::json v = request.value(key, nlohmann::json());
  return v.is_string() ? std::filesystem::path(v.get<std::string>()) : std::filesystem::path();
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
    throw InputError("--param: method " + method + " has no parameter '" + key + "' (it has: " + names + ")");
  }
}

RenderRequest render_request(py::handle scene, py::handle gbuffer, const nlohmann::json& q) {
  RenderRequest r;
  if (!gbuffer.is_none()) r.gbuffer = gbuffer.cast<const GBufferHandle&>().gbuffer;
  else r.scene = scene_source(scene);
  r.method = q.value("method", std::string("raytraced"));
  r.params = object_of(q, "params");
  check_param_names(r.method, r.params);
  if (q.contains("samples") && !q["samples"].is_null()) r.samples = q["samples"].get<int>();
  if (q.contains("target_error") && !q["target_error"].is_null()) r.target_error = q["target_error"].get<float>();
  r.camera = camera_request(q, r.camera);
  r.falloff = falloff_request(q);
  if (q.contains("normal") && !q["normal"].is_null()) r.normal = surface_normal_from_name(q["normal"].get<std::string>());
  r.seed = seed_of(q);
  r.outputs.visibility = path_of(q, "output");
  r.outputs.shaded = path_of(q, "shaded");
  r.outputs.gbuffer = path_of(q, "gbuffer_output");
  r.outputs.png_bits = q.value("png_bits", 8);
  r.outputs.extras = q.value("extras", false);
  return r;
}

}  // namespace

py::dict render(py::handle scene, py::handle gbuffer, py::handle request) {
  const nlohmann::json q = to_json(request, "request");
  const RenderRequest r = render_request(scene, gbuffer, q);
  Call call;
  RenderResult out = call.run([&] { return run_render(r, call.reporter()); });
  py::dict d;
  d["visibility"] = to_array(std::move(out.output.visibility));
  if (!out.output.std_error.empty()) d["std_error"] = to_array(std::move(out.output.std_error));
  if (!out.output.color.empty()) d["color"] = to_array(std::move(out.output.color));
  py::dict extras;
  for (auto& [name, image] : out.output.extras) extras[py::str(name)] = to_array(std::move(image));
  d["extras"] = extras;
  d["summary"] = from_json(out.summary);
  if (q.value("return_gbuffer", false)) d["gbuffer"] = GBufferHandle{std::make_shared<const GBuffer>(std::move(out.gbuffer))};
  return d;
}

GBufferHandle gbuffer(py::handle scene, py::handle request) {
  const nlohmann::json q = to_json(request, "request");
  const SceneSource source = scene_source(scene);
  const CameraRequest camera = camera_request(q, CameraRequest{});
  const GBufferOptions options{.normal = surface_normal_from_name(q.value("normal", std::string("shading"))), .albedo = q.value("albedo", true),
                               .uv = q.value("uv", false)};
  Call call;
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
    if (!params["denoise"].is_number()) throw InputError("--denoise: expected a number of texels, got " + params["denoise"].dump());
    r.denoise = params["denoise"].get<float>();
    params.erase("denoise");
  }
  if (r.method == Baker::Histogram) histogram_param_table().from_json(params, r.histogram);
  else raytraced_bake_param_table().from_json(params, r.raytraced);
}

// `files`: set when the request names files to write (then a mesh file is baked by the job as
// `ao bake` bakes it, outputs included).
BakeRequest bake_request(py::handle mesh, const nlohmann::json& q, bool& files) {
  BakeRequest r;
  r.method = baker_from_name(q.value("method", std::string("raytraced")));
  if (q.contains("size") && !q["size"].is_null()) r.size = parse_map_size(q["size"].is_string() ? q["size"].get<std::string>() : q["size"].dump());
  r.uv_set = q.value("uv_set", 0);
  r.padding = q.value("padding", r.padding);
  r.vertex_resolution = q.value("vertex_resolution", r.vertex_resolution);
  bake_params(r, object_of(q, "params"));
  r.outputs.map = path_of(q, "output");
  r.outputs.per_vertex = path_of(q, "per_vertex_output");
  r.outputs.bent_normals = path_of(q, "bent_normals_output");
  r.outputs.gltf = path_of(q, "gltf_output");
  if (q.contains("png_bits") && !q["png_bits"].is_null()) r.outputs.png_bits = q["png_bits"].get<int>();
  files = !r.outputs.map.empty() || !r.outputs.per_vertex.empty() || !r.outputs.bent_normals.empty() || !r.outputs.gltf.empty();
  if (py::isinstance<SceneHandle>(mesh)) {
    if (files) throw InputError("ao.bake: outputs are written for mesh files; bake a mesh made from arrays and save the arrays");
    r.scene = mesh.cast<const SceneHandle&>().scene;
  } else {
    const nlohmann::json path = to_json(mesh, "mesh");
    if (!path.is_string()) throw InputError("mesh: expected a mesh file or an ao.Scene, got " + path.dump());
    r.inputs = {path.get<std::string>()};
    if (std::filesystem::is_directory(r.inputs.front()))
      throw InputError(r.inputs.front().string() + ": ao.bake bakes one mesh; bake a folder with python3 -m ao.batch bake");
  }
  // Without files, what to compute: the job bakes a map unless only per-vertex AO is named, and
  // writes nothing for a mesh in memory (these names only say what to bake).
  if (!files) {
    if (q.value("map", true)) r.outputs.map = "map.png";
    if (q.value("per_vertex", false)) r.outputs.per_vertex = "per-vertex.ply";
    if (r.outputs.map.empty() && r.outputs.per_vertex.empty()) throw InputError("ao.bake: nothing to bake: ask for the map or per_vertex");
  }
  return r;
}

}  // namespace

py::dict bake(py::handle mesh, py::handle request) {
  const nlohmann::json q = to_json(request, "request");
  bool files = false;
  BakeRequest r = bake_request(mesh, q, files);
  Call call;
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
  if (!m.vertex_ao.empty()) {
    auto* held = new std::vector<float>(std::move(m.vertex_ao));
    d["per_vertex"] = py::array_t<float>({static_cast<py::ssize_t>(held->size())}, {static_cast<py::ssize_t>(sizeof(float))}, held->data(),
                                         py::capsule(held, [](void* p) { delete static_cast<std::vector<float>*>(p); }));
  }
  d["summary"] = from_json(m.summary);
  return d;
}

namespace {

CompareRequest compare_request(py::handle scene, const nlohmann::json& q) {
  CompareRequest r;
  r.scene = scene_source(scene);
  r.camera = camera_request(q, r.camera);
  r.falloff = falloff_request(q);
  r.normal = surface_normal_from_name(q.value("normal", std::string("shading")));
  CompareSettings& s = r.settings;
  if (q.contains("methods") && !q["methods"].is_null()) s.methods = q["methods"].get<std::vector<std::string>>();
  // Each method's overrides over its defaults, as `ao compare -p method.key=value` sets them.
  const nlohmann::json per_method = object_of(q, "params");
  for (const auto& [name, overrides] : per_method.items()) {
    nlohmann::json p = find_method(name).default_params();
    if (!overrides.is_object()) throw InputError("params." + name + ": expected a dict of parameters, got " + overrides.dump());
    check_param_names(name, overrides);
    for (const auto& [k, v] : overrides.items()) p[k] = v;
    s.params[name] = p;
  }
  const nlohmann::json ref = q.value("reference", nlohmann::json());
  if (ref.is_string()) s.references[""] = ref.get<std::string>();
  else if (ref.is_object()) s.references = ref.get<std::map<std::string, std::string>>();
  s.common_reference = q.value("common_reference", s.common_reference);
  s.spp_reference = q.value("spp_reference", s.spp_reference);
  s.seed = seed_of(q);
  const nlohmann::json sweep = q.value("sweep", nlohmann::json());
  if (sweep.is_object() && sweep.size() == 1) {
    s.sweep_key = sweep.begin().key();
    s.sweep_values = sweep.begin().value().get<std::vector<nlohmann::json>>();
  } else if (!sweep.is_null()) {
    throw InputError("sweep: expected {key: [values]} for one parameter, got " + sweep.dump());
  }
  r.out_dir = path_of(q, "out_dir");
  // The sheet's font as `ao compare` finds it: $AO_FONT when set, else DejaVu Sans.
  if (const char* env = std::getenv("AO_FONT"); env != nullptr && *env != 0) r.font = env;
  return r;
}

}  // namespace

py::dict compare(py::handle scene, py::handle request) {
  const nlohmann::json q = to_json(request, "request");
  const CompareRequest r = compare_request(scene, q);
  Call call;
  CompareJobResult out = call.run([&] { return run_compare(r, call.reporter()); });
  py::dict d;
  d["table"] = from_json(out.table);
  d["markdown"] = out.markdown;
  if (q.value("images", false)) {
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
