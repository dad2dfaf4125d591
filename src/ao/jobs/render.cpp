// SPDX-License-Identifier: Apache-2.0
#include "ao/jobs/render.h"

#include <cctype>
#include <chrono>

#include <nlohmann/json.hpp>

#include "ao/core/closest_name.h"
#include "ao/core/error.h"
#include "ao/core/memory.h"
#include "ao/eval/shading.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/registry/methods_gpu.h"
#include "ao/io/gbuffer_exr.h"
#include "ao/io/image_io.h"
#include "ao/io/json_text.h"
#include "ao/io/output_set.h"
#include "ao/jobs/fields.h"
#include "ao/jobs/provenance.h"
#include "ao/jobs/render_view.h"
#include "ao/core/stopwatch.h"
#include "ao/reference/ray_scene.h"

namespace ao {

namespace {

namespace fs = std::filesystem;

constexpr const char* kAoMapMethod = "ao-map";

bool has_gbuffer_input(const RenderRequest& r) { return r.gbuffer || !r.gbuffer_file.empty(); }

// The parameters of the run: the method's, or none when an AO map is shown instead.
std::optional<MethodParams> request_params(const RenderRequest& r, const MethodInfo& m) {
  if (!r.ao_map.empty()) return std::nullopt;
  return method_params(m, r.params, r.samples, r.target_error);
}

void check_outputs(const RenderOutputs& o) {
  if (o.png_bits != 8 && o.png_bits != 16) throw InputError(field(fields::kRenderPngBits) + " must be 8 or 16, got " + std::to_string(o.png_bits));
  for (const fs::path& out : {o.visibility, o.shaded})
    if (!out.empty() && !is_supported_image_path(out))
      throw InputError(out.string() + ": unknown image extension (supported: " + supported_image_extensions() + ")" +
                       did_you_mean(out.extension().string(), supported_image_extensions()));
  if (!o.gbuffer.empty() && o.gbuffer.extension() != ".exr")
    throw InputError(o.gbuffer.string() + ": " + field(fields::kRenderGBufferOut) + " writes OpenEXR, give it a .exr name");
}

// <output-stem>-<name><ext>, beside the output.
fs::path extra_path(const fs::path& output, std::string_view name) {
  return output.parent_path() / (output.stem().string() + "-" + std::string(name) + output.extension().string());
}

// Every file of the run, declared before the work: one that names an input or another output is
// refused now, and they are renamed into place together at the end.
void declare_outputs(OutputSet& set, const RenderRequest& r, const MethodInfo& m) {
  r.scene.declare_inputs(set);
  set.add_input(r.gbuffer_file, field(fields::kRenderGBufferFile));
  set.add_input(r.ao_map, field(fields::kRenderAoMap));
  const RenderOutputs& o = r.outputs;
  if (!o.visibility.empty()) set.add_output(o.visibility, o.visibility == default_render_output(r) ? "the default output" : field(fields::kRenderVisibility));
  if (!o.shaded.empty()) set.add_output(o.shaded, field(fields::kRenderShaded));
  if (!o.gbuffer.empty()) set.add_output(o.gbuffer, field(fields::kRenderGBufferOut));
  if (o.extras && r.ao_map.empty() && !o.visibility.empty())
    for (std::string_view name : m.extras) set.add_output(extra_path(o.visibility, name), field(fields::kRenderExtras));
  if (o.provenance) {
    if (r.gbuffer)
      throw InputError(field(fields::kRenderProvenance) + ": a G-buffer made in memory has no file to record; render from a scene or a G-buffer file");
    if (set.outputs().empty()) throw InputError(field(fields::kRenderProvenance) + " records how outputs were made: name an output file");
    declare_provenance(set, set.outputs(), field(fields::kRenderProvenance));
  }
}

nlohmann::json vec3_json(const std::optional<Vec3>& v) { return v ? nlohmann::json::array({v->x, v->y, v->z}) : nlohmann::json(); }

// What the record of a render calls its settings: every field that changes an output.
nlohmann::json render_settings(const RenderRequest& r, const nlohmann::json& params) {
  const CameraRequest& c = r.camera;
  const FalloffRequest& f = r.falloff;
  nlohmann::json s = {
      {"scene", r.scene.files().empty() && !has_gbuffer_input(r) ? r.scene.name() : std::string()},  // files are inputs
      {"method", r.ao_map.empty() ? r.method : std::string(kAoMapMethod)},
      {"parameters", params},
      {"camera", {{"eye", vec3_json(c.eye)}, {"target", vec3_json(c.target)}, {"up", vec3_json(c.up)}, {"fov", c.fov ? nlohmann::json(*c.fov) : nlohmann::json()},
                  {"width", c.width.value_or(c.file ? 0 : c.default_width)}, {"height", c.height.value_or(c.file ? 0 : c.default_height)}}},
      {"membership", to_string(f.membership)},
      {"radius", f.radius ? nlohmann::json(*f.radius) : nlohmann::json()},
      {"radius_fraction", f.radius ? nlohmann::json() : nlohmann::json(f.radius_fraction)},
      {"tau", f.tau},
      {"normal", r.normal ? to_string(*r.normal) : has_gbuffer_input(r) ? "file" : "shading"},
      {"seed", r.seed},
      {"device", to_string(r.device)},
      {"png_bits", r.outputs.png_bits},
  };
  if (r.sun) s["sun"] = {{"direction", vec3_json(r.sun->direction)}, {"irradiance", r.sun->irradiance}};
  if (r.scene.scene) s["scene_sha256"] = scene_sha256(*r.scene.scene);
  return s;
}

void check_memory_of(const RenderRequest& r, const std::optional<MethodParams>& params) {
  if (has_gbuffer_input(r)) return;
  const int width = r.camera.width.value_or(r.camera.default_width), height = r.camera.height.value_or(r.camera.default_height);
  const MethodMemory extra = params ? extra_memory(*params) : MethodMemory{};
  check_memory(estimate_render_memory({.width = width, .height = height, .sun = r.sun.has_value(), .shaded = !r.outputs.shaded.empty(),
                                       .gbuffer_out = !r.outputs.gbuffer.empty()}) +
                   extra.bytes,
               "ao render: " + std::to_string(width) + "x" + std::to_string(height) + " pixels" + (extra.bytes ? " and " + extra.what : ""));
}

// What the render reads, loaded: the scene and its BVH (or the G-buffer), and the AO map.
struct Loaded {
  std::optional<PreparedScene> scene;
  GBuffer gbuffer;
  float diagonal = 0;
  Image<float> ao_map;
};

float covered_diagonal(const GBuffer& g) {
  Bounds3 b;
  for (std::size_t i = 0; i < g.position.size(); ++i)
    if (g.covered(i)) b.extend(g.position[i]);
  return b.diagonal();
}

Loaded load_inputs(const RenderRequest& r, const MethodInfo& m, const JobReporter& reporter, nlohmann::json& timings, Stopwatch& clock) {
  Loaded in;
  if (!r.ao_map.empty()) in.ao_map = read_image(r.ao_map);
  if (has_gbuffer_input(r)) {
    in.gbuffer = r.gbuffer ? *r.gbuffer : read_gbuffer_exr(r.gbuffer_file, {.vertical_fov_deg = r.camera.fov});
    timings["load_gbuffer_ms"] = clock.lap_ms();
    in.diagonal = covered_diagonal(in.gbuffer);
    return in;
  }
  std::shared_ptr<const Scene> scene = r.scene.load();
  for (const std::string& w : scene->warnings) reporter.warn(w);
  timings["load_ms"] = clock.lap_ms();
  in.scene.emplace(std::move(scene), "ao render", BvhOptions{});
  timings["bvh_ms"] = clock.lap_ms();
  const Camera cam = choose_camera(*in.scene->scene, r.camera);
  const GBufferOptions options = gbuffer_options_for(m, r.normal.value_or(SurfaceNormal::Shading),
                                                     r.sun || r.shade || !r.outputs.shaded.empty() || !r.outputs.gbuffer.empty(), !r.ao_map.empty());
  in.gbuffer = render_gbuffer(*in.scene->rays, cam, options, reporter.start("G-buffer"));
  timings["gbuffer_ms"] = clock.lap_ms();
  in.diagonal = in.scene->radius_basis;
  if (r.sun) {
    in.gbuffer.direct = render_direct_light(*in.scene->rays, in.gbuffer, *r.sun, reporter.start("sun"));
    timings["direct_ms"] = clock.lap_ms();
  }
  return in;
}

// .exr in any case, as write_image chooses the format.
bool is_exr(const fs::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".exr";
}

// The method on the GPU, on the G-buffer the render made (uploaded, with the scene for cone).
void run_on_gpu(GpuDevice& device, const MethodParams& params, const Loaded& in, std::uint32_t seed, RenderResult& out) {
  const RayScene* rays = in.scene ? in.scene->rays.get() : nullptr;
  GpuMethodOutput g = run_gpu_method(device, MethodInput{in.gbuffer, rays, out.falloff, seed}, params);
  out.output = std::move(g.output);
  out.gpu_passes = std::move(g.passes);
  out.gl_renderer = std::move(g.renderer);
}

void write_outputs(OutputSet& set, const RenderRequest& r, RenderResult& result, const nlohmann::json& record) {
  const RenderOutputs& o = r.outputs;
  const ImageWriteOptions write_opt{.png_bits = o.png_bits};
  const Image<std::uint8_t> coverage = coverage_mask(result.gbuffer);
  // A picture (PNG, TIFF, TGA, JPEG) shows the background as display_background, never as open
  // surface (V = 1, white); EXR is data and keeps V = 1 there, what scripts read (with the
  // G-buffer's coverage, --gbuffer-out, for compositing).
  auto write_v = [&](const fs::path& path, const Image<float>& v) {
    write_image(path, is_exr(path) ? v : with_display_background(v, coverage), write_opt);
  };
  if (!o.visibility.empty()) set.write(o.visibility, [&] { write_v(o.visibility, result.output.visibility); });
  if (!o.shaded.empty()) set.write(o.shaded, [&] { write_rgb_image(o.shaded, result.shaded, {.png_bits = o.png_bits, .srgb = true}); });
  if (o.extras && !o.visibility.empty())
    for (const auto& extra : result.output.extras) {
      const std::string& name = extra.first;
      const auto& image = extra.second;  // a named reference: Clang 14 cannot capture structured bindings
      const fs::path path = extra_path(o.visibility, name);
      set.write(path, [&] { write_v(path, image); }, field(fields::kRenderExtras));
      result.extras_written[name] = path;
    }
  if (!o.gbuffer.empty()) set.write(o.gbuffer, [&] { write_gbuffer_exr(o.gbuffer, result.gbuffer); });
  if (o.provenance) stage_provenance(set, record);
  set.commit();
}

nlohmann::json to_json(Vec3 v) { return nlohmann::json::array({v.x, v.y, v.z}); }

nlohmann::json summary_of(const RenderRequest& r, const RenderResult& out, const Scene* scene, const nlohmann::json& timings) {
  const Camera& c = out.gbuffer.camera;
  nlohmann::json extras = nlohmann::json::object();
  for (const auto& [name, path] : out.extras_written) extras[name] = path.string();
  nlohmann::json s = {
      {"ao", build_info()},
      {"scene", out.scene},
      {"method", out.method},
      {"parameters", out.params},
      {"membership", to_string(out.falloff.membership)},
      {"radius", out.falloff.radius},
      {"normal", out.normal},
      {"seed", r.seed},
      {"width", out.gbuffer.width()},
      {"height", out.gbuffer.height()},
      {"camera", {{"eye", to_json(c.eye)}, {"target", to_json(c.target)}, {"up", to_json(c.up)}, {"fov", c.vertical_fov_deg}}},
      {"covered_pixels", out.covered_pixels},
      {"mean_visibility", out.mean_visibility},
      {"timings", timings},
      {"output", r.outputs.visibility.string()},
      {"extras", extras},
      {"stats", out.output.stats},
  };
  if (out.falloff.membership == Membership::Exp) s["tau"] = out.falloff.effective_tau();
  if (r.sun) s["sun"] = {{"direction", to_json(r.sun->direction)}, {"irradiance", r.sun->irradiance}};
  if (scene) {
    s["triangles"] = scene->triangle_count();
    s["instances"] = scene->instances.size();
    s["warnings"] = scene->warnings;
  }
  s["device"] = to_string(out.device);
  if (out.device == Device::Gpu) {
    s["gl_renderer"] = out.gl_renderer;
    s["gpu_passes"] = gpu_passes_json(out.gpu_passes);
  }
  if (out.output.stats->contains("rays") && out.method_ms > 0)
    s["rays_per_second"] = out.output.stats["rays"].get<double>() / (out.method_ms / 1000.0);
  return s;
}

}  // namespace

void check_device(Device device, const MethodParams& params) {
  if (device == Device::Gpu) check_gpu_method(params);
}

MethodParams method_params(const MethodInfo& method, const nlohmann::json& overrides, std::optional<int> samples,
                           std::optional<float> target_error) {
  nlohmann::json params = nlohmann::json::object();
  if (samples) {
    if (method.samples_param.empty()) throw InputError(field(fields::kRenderSamples) + ": method " + std::string(method.name) + " has no sample count");
    params[std::string(method.samples_param)] = *samples;
  }
  if (target_error) {
    if (method.target_error_param.empty()) throw InputError(field(fields::kRenderTargetError) + ": only the ray-traced method stops adaptively");
    params[std::string(method.target_error_param)] = *target_error;
  }
  if (!overrides.is_null()) {
    if (!overrides.is_object()) throw InputError(std::string(method.name) + ": parameters must be a JSON object, got " + json_excerpt(overrides));
    for (const auto& [key, value] : overrides.items()) params[key] = value;
  }
  return method.decode(params);
}

GBufferOptions gbuffer_options_for(const MethodInfo& method, SurfaceNormal normal, bool albedo_for_outputs, bool uv) {
  // Only the channels something reads: screen-space methods read the albedo (transfer, GTAO's
  // multi-bounce); the ray tracers take it from the scene. UVs serve an AO map only.
  return {.normal = normal, .albedo = !method.needs_scene || albedo_for_outputs, .uv = uv};
}

GBuffer render_view_gbuffer(const PreparedScene& scene, const Camera& camera, const GBufferOptions& options, const std::optional<Sun>& sun,
                            const JobReporter& reporter) {
  GBuffer g = render_gbuffer(*scene.rays, camera, options, reporter.start("G-buffer"));
  if (sun) g.direct = render_direct_light(*scene.rays, g, *sun, reporter.start("sun"));
  return g;
}

MethodOutput run_on_scene(const MethodParams& params, const GBuffer& gbuffer, const PreparedScene* scene, const Falloff& falloff,
                          std::uint32_t seed, MethodCache* cache, const ProgressFn& progress) {
  return run_method(MethodInput{gbuffer, scene ? scene->rays.get() : nullptr, falloff, seed, progress, scene ? &scene->scene->analytic : nullptr, cache},
                    params);
}

void check_render_request(const RenderRequest& r) {
  const MethodInfo& m = find_method(r.method);
  const bool gbuffer_input = has_gbuffer_input(r);
  if (gbuffer_input && (r.scene.scene || !r.scene.args.empty())) throw InputError("give either " + field(fields::kRenderScene) + " or " + field(fields::kRenderGBufferFile) + ", not both");
  if (!r.ao_map.empty() && gbuffer_input) throw InputError(field(fields::kRenderAoMap) + " needs the scene's UVs: give a scene, not " + field(fields::kRenderGBufferFile));
  if (!r.ao_map.empty() && !m.ground_truth) throw InputError(field(fields::kRenderAoMap) + " shows a baked map instead of a method: drop " + field(fields::kRenderMethod));
  if (!r.ao_map.empty() && (r.samples || r.target_error)) throw InputError(field(fields::kRenderAoMap) + " shows a baked map: " + field(fields::kRenderSamples) + " and " + field(fields::kRenderTargetError) + " do not apply");
  check_outputs(r.outputs);
  if (gbuffer_input && m.needs_scene)
    throw InputError("method " + std::string(m.name) + " traces rays in the scene, and " + field(fields::kRenderGBufferFile) + " gives only a G-buffer: pass a scene instead");
  r.camera.validate();
  r.falloff.validate();
  const std::optional<MethodParams> params = request_params(r, m);
  if (r.device == Device::Gpu && !r.ao_map.empty())
    throw InputError(field(fields::kRenderAoMap) + " shows a baked map instead of running a method: " + field(fields::kDevice) + " gpu does not apply");
  if (params) check_device(r.device, *params);
  if (r.normal && gbuffer_input)
    throw InputError(field(fields::kNormal) + " chooses the normal a scene's G-buffer is rendered with; a " + field(fields::kRenderGBufferFile) + " file brings its own N");
  if (r.sun) r.sun->validate();
  if (r.sun && gbuffer_input)
    throw InputError(field(fields::kRenderSun) + " traces shadow rays in the scene, and " + field(fields::kRenderGBufferFile) + " gives only a G-buffer: give a scene, or a G-buffer EXR with "
                     "direct.R direct.G direct.B channels");
  if (params && reads_direct_light(*params) && !r.sun && !gbuffer_input)
    throw InputError(field(fields::kRenderParams) + " reflectance=radiance reads the occluders' direct light: give a sun with " + field(fields::kRenderSun) + " (or " +
                     field(fields::kRenderGBufferFile) + " with direct.R direct.G direct.B channels)");
}

nlohmann::json render_provenance(const RenderRequest& r, bool hash_inputs) {
  check_render_request(r);
  std::vector<ProvenanceInput> inputs;
  for (const std::string& a : r.scene.files())
    for (const fs::path& f : files_read_by(a)) inputs.push_back({"scene", f});
  if (r.camera.file) inputs.push_back({"camera", *r.camera.file});
  if (!r.gbuffer_file.empty()) inputs.push_back({"gbuffer", r.gbuffer_file});
  if (!r.ao_map.empty()) inputs.push_back({"ao_map", r.ao_map});
  const std::optional<MethodParams> params = request_params(r, find_method(r.method));
  return provenance_record("render", inputs, render_settings(r, params ? params_json(*params) : nlohmann::json::object()), hash_inputs);
}

fs::path default_render_output(const RenderRequest& r) {
  std::string stem = fs::path(has_gbuffer_input(r) ? r.gbuffer_file : fs::path(r.scene.name())).stem().string();
  if (stem.empty()) stem = "gbuffer";
  return stem + "-" + (r.ao_map.empty() ? r.method : std::string(kAoMapMethod)) + ".png";
}

RenderResult run_render(const RenderRequest& r, const JobReporter& reporter) {
  Stopwatch clock;
  nlohmann::json timings;
  check_render_request(r);
  const MethodInfo& m = find_method(r.method);
  RenderResult out;
  out.method = r.ao_map.empty() ? std::string(m.name) : kAoMapMethod;
  const std::optional<MethodParams> params = request_params(r, m);
  out.params = params ? params_json(*params) : nlohmann::json::object();
  OutputSet outputs;
  declare_outputs(outputs, r, m);
  check_memory_of(r, params);
  // The inputs are hashed as the run starts, before they are read.
  const nlohmann::json record = r.outputs.provenance ? render_provenance(r) : nlohmann::json();
  std::optional<GpuDevice> gpu;
  if (r.device == Device::Gpu) {  // before anything is loaded: without a usable OpenGL the run stops here
    gpu = GpuDevice::open();
    timings["device_ms"] = clock.lap_ms();
  }

  Loaded in = load_inputs(r, m, reporter, timings, clock);
  const bool gbuffer_input = !in.scene;
  if (params && reads_direct_light(*params) && in.gbuffer.direct.empty())
    throw InputError(r.gbuffer_file.string() + ": " + field(fields::kRenderParams) + " reflectance=radiance reads the occluders' direct light, and the file has no direct.R direct.G "
                     "direct.B channels (docs/gbuffer.md)");
  out.falloff = choose_falloff(r.falloff, in.diagonal);
  if (!in.ao_map.empty()) {
    out.output.visibility = visibility_from_ao_map(in.gbuffer, *in.scene->scene, in.ao_map, r.ao_map.string());
    out.output.stats = nlohmann::json{{"ao_map", r.ao_map.string()}, {"map_width", in.ao_map.width()}, {"map_height", in.ao_map.height()}};
  } else if (gpu) {
    reporter.start(out.method + " (gpu)");
    run_on_gpu(*gpu, *params, in, r.seed, out);
  } else {
    out.output = run_on_scene(*params, in.gbuffer, in.scene ? &*in.scene : nullptr, out.falloff, r.seed, nullptr, reporter.start(out.method));
  }
  out.device = gpu ? Device::Gpu : Device::Cpu;
  out.method_ms = clock.lap_ms();
  timings["ao_ms"] = out.method_ms;
  // Methods report problems they worked around (e.g. cone: open meshes, odd voxel columns).
  if (out.output.stats->contains("warnings"))
    for (const auto& w : out.output.stats["warnings"]) reporter.warn(w.get<std::string>());

  out.gbuffer = std::move(in.gbuffer);
  if (r.shade || !r.outputs.shaded.empty()) out.shaded = shade_for_display(out.gbuffer, out.output.visibility, out.output.color);
  write_outputs(outputs, r, out, record);
  timings["write_ms"] = clock.lap_ms();

  double sum_v = 0;
  for (std::size_t i = 0; i < out.gbuffer.object_id.size(); ++i)
    if (out.gbuffer.covered(i)) {
      sum_v += out.output.visibility[i];
      ++out.covered_pixels;
    }
  out.mean_visibility = out.covered_pixels ? sum_v / static_cast<double>(out.covered_pixels) : 1.0;
  out.scene = gbuffer_input ? (r.gbuffer ? std::string("gbuffer") : r.gbuffer_file.string()) : in.scene->scene->name;
  out.normal = gbuffer_input ? "file" : to_string(r.normal.value_or(SurfaceNormal::Shading));
  out.summary = summary_of(r, out, in.scene ? in.scene->scene.get() : nullptr, timings);
  return out;
}

}  // namespace ao
