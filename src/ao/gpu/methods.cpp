// run_gpu_method (methods.h): parameters through the methods' tables, then the method's passes.
#include "ao/gpu/methods.h"

#include <algorithm>
#include <array>
#include <optional>
#include <string>

#include "ao/core/error.h"
#include "ao/gpu/methods_internal.h"
#include "ao/reference/ray_scene.h"

namespace ao {

namespace {

constexpr std::array<std::string_view, 6> kGpuMethods{"containment", "volumetric", "transfer", "cone", "alchemy", "gtao"};

// `j` read through method `m`'s parameter table by the registry (unknown keys, types, ranges and
// the characteristic's names are checked there, with its messages), into Params. Of the
// characteristic functions (registry.h) the GPU reads the depth buffer only.
template <class Params>
Params params_of(const MethodInfo& m, const nlohmann::json& j) {
  nlohmann::json c = m.canonical_params(j);
  if (c.contains(kCharacteristicParam)) {
    const std::string kind = c.at(kCharacteristicParam).get<std::string>();
    if (kind != "depth")
      throw InputError(std::string(m.name) + " on the GPU reads the depth buffer only: characteristic " + kind + " runs on the CPU (--device cpu)");
    c.erase(kCharacteristicParam);
  }
  return c.get<Params>();
}

// The registry's row of `method`, when the GPU runs it.
const MethodInfo& gpu_method(std::string_view method) {
  const MethodInfo& m = find_method(method);  // InputError listing the methods for an unknown name
  if (std::find(kGpuMethods.begin(), kGpuMethods.end(), method) == kGpuMethods.end())
    throw InputError("method " + std::string(m.name) + " runs on the CPU only (--device cpu); the GPU runs containment, volumetric, transfer, cone, alchemy, gtao");
  return m;
}

}  // namespace

std::span<const std::string_view> gpu_method_names() { return kGpuMethods; }

void check_gpu_method(std::string_view method, const nlohmann::json& params) {
  const MethodInfo& m = gpu_method(method);
  if (method == "containment") params_of<ContainmentParams>(m, params);
  else if (method == "volumetric") params_of<VolumetricParams>(m, params);
  else if (method == "transfer") params_of<TransferParams>(m, params);
  else if (method == "alchemy") params_of<AlchemyParams>(m, params);
  else if (method == "gtao") params_of<GtaoParams>(m, params);
  else if (params_of<ConeParams>(m, params).resolved().grid == GridSpace::Eye)
    throw InputError("cone on the GPU traces the world grid only: grid=eye runs on the CPU (--device cpu)");
}

GpuMethodOutput run_gpu_method(GpuDevice& device, std::string_view method, const GpuMethodInput& in, const nlohmann::json& params) {
  using namespace gpu_detail;
  Context& c = Access::context(device);
  if (Access::textures(in.gbuffer).context.get() != &c) throw InputError("--device gpu: the G-buffer was made on another device");
  const MethodInfo& m = gpu_method(method);
  c.make_current();
  Run r{c, Access::textures(in.gbuffer), {}};
  GpuMethodOutput out;
  if (method == "containment") out.output = run_containment(r, in.falloff, params_of<ContainmentParams>(m, params), in.seed);
  else if (method == "volumetric") out.output = run_volumetric(r, in.falloff, params_of<VolumetricParams>(m, params), in.seed);
  else if (method == "transfer") out.output = run_transfer(r, in.falloff, params_of<TransferParams>(m, params), in.seed);
  else if (method == "alchemy") out.output = run_alchemy(r, in.falloff, params_of<AlchemyParams>(m, params), in.seed);
  else if (method == "gtao") out.output = run_gtao(r, in.falloff, params_of<GtaoParams>(m, params), in.seed);
  else {
    const ConeParams p = params_of<ConeParams>(m, params);
    if (!in.scene) throw InputError("method cone voxelizes the scene, and a G-buffer file has none: give a scene instead of --gbuffer-in");
    if (Access::buffers(*in.scene).context.get() != &c) throw InputError("--device gpu: the scene was uploaded to another device");
    out.output = run_cone(r, Access::buffers(*in.scene), in.falloff, p, in.seed);
  }
  c.check(std::string("running ") + std::string(method));
  out.passes = c.resolve(r.passes);
  out.renderer = c.renderer;
  nlohmann::json ms = nlohmann::json::object();
  for (const GpuPassTime& p : out.passes) ms[p.name] = ms.value(p.name, 0.0) + p.ms;
  if (!out.output.stats.is_object()) out.output.stats = nlohmann::json::object();
  out.output.stats["device"] = c.renderer;
  out.output.stats["gpu_ms"] = ms;
  // The CPU methods' own timings in --json, from the GPU passes that do their work.
  const auto pass_ms = [&](std::initializer_list<const char*> names) {
    double sum = 0;
    for (const char* n : names) sum += ms.value(n, 0.0);
    return sum;
  };
  if (method == "cone") {
    out.output.stats["voxelize_ms"] = pass_ms({"voxelize", "count"});
    out.output.stats["trace_ms"] = pass_ms({"cone"});
    out.output.stats["filter_ms"] = pass_ms({"filter"});
  } else if (method == "alchemy") {
    out.output.stats["estimator_ms"] = pass_ms({"alchemy"});
    out.output.stats["filter_ms"] = pass_ms({"filter"});
  }
  return out;
}

GpuMethodOutput run_gpu_method(GpuDevice& device, std::string_view method, const MethodInput& in, const nlohmann::json& params) {
  const GpuGBuffer g = GpuGBuffer::upload(device, in.gbuffer);
  std::optional<GpuScene> scene;
  if (method == "cone" && in.scene) scene = GpuScene::upload(device, in.scene->scene());
  GpuMethodOutput out = run_gpu_method(device, method, GpuMethodInput{g, scene ? &*scene : nullptr, in.falloff, in.seed}, params);
  out.passes.insert(out.passes.begin(), g.passes().begin(), g.passes().end());
  out.output.stats["gpu_ms"]["upload"] = g.passes().front().ms;
  return out;
}

}  // namespace ao
