// run_gpu_method (methods.h): parameters through the methods' tables, then the method's passes.
#include "ao/gpu/methods.h"

#include <array>
#include <optional>
#include <string>

#include "ao/core/error.h"
#include "ao/gpu/methods_internal.h"
#include "ao/reference/ray_scene.h"

namespace ao {

namespace {

constexpr std::array<std::string_view, 6> kGpuMethods{"containment", "volumetric", "transfer", "cone", "alchemy", "gtao"};

// The parameters of a screen-space method with the registry's characteristic choice (registry.h):
// the GPU reads the depth buffer only.
template <class Params>
Params screen_space_params(std::string_view method, const nlohmann::json& j) {
  nlohmann::json rest = j;
  if (rest.is_object() && rest.contains(kCharacteristicParam)) {
    const nlohmann::json value = rest.at(kCharacteristicParam);
    rest.erase(kCharacteristicParam);
    if (value != "depth") {
      bool known = false;
      for (std::string_view n : characteristic_names()) known = known || value == n;
      if (!known) {
        std::string names;
        for (std::string_view n : characteristic_names()) names += (names.empty() ? "" : ", ") + std::string(n);
        throw InputError(std::string(method) + ": characteristic must be one of " + names + ", got " + value.dump());
      }
      throw InputError(std::string(method) + " on the GPU reads the depth buffer only: characteristic " + value.get<std::string>() +
                       " runs on the CPU (--device cpu)");
    }
  }
  Params p = rest.get<Params>();
  p.validate();
  return p;
}

template <class Params>
Params table_params(const nlohmann::json& j) {
  Params p = j.get<Params>();
  p.validate();
  return p;
}

}  // namespace

std::span<const std::string_view> gpu_method_names() { return kGpuMethods; }

GpuMethodOutput run_gpu_method(GpuDevice& device, std::string_view method, const GpuMethodInput& in, const nlohmann::json& params) {
  using namespace gpu_detail;
  Context& c = Access::context(device);
  if (Access::textures(in.gbuffer).context.get() != &c) throw InputError("--device gpu: the G-buffer was made on another device");
  bool known = false;
  for (std::string_view n : kGpuMethods) known = known || n == method;
  if (!known) {
    const MethodInfo& m = find_method(method);  // InputError listing the methods for an unknown name
    throw InputError("method " + std::string(m.name) + " runs on the CPU only (--device cpu); the GPU runs containment, volumetric, transfer, cone, alchemy, gtao");
  }
  c.make_current();
  Run r{c, Access::textures(in.gbuffer), {}};
  GpuMethodOutput out;
  if (method == "containment") out.output = run_containment(r, in.falloff, screen_space_params<ContainmentParams>(method, params), in.seed);
  else if (method == "volumetric") out.output = run_volumetric(r, in.falloff, screen_space_params<VolumetricParams>(method, params), in.seed);
  else if (method == "transfer") out.output = run_transfer(r, in.falloff, screen_space_params<TransferParams>(method, params), in.seed);
  else if (method == "alchemy") out.output = run_alchemy(r, in.falloff, table_params<AlchemyParams>(params), in.seed);
  else if (method == "gtao") out.output = run_gtao(r, in.falloff, table_params<GtaoParams>(params), in.seed);
  else {
    if (!in.scene) throw InputError("method cone voxelizes the scene, and a G-buffer file has none: give a scene instead of --gbuffer-in");
    if (Access::buffers(*in.scene).context.get() != &c) throw InputError("--device gpu: the scene was uploaded to another device");
    out.output = run_cone(r, Access::buffers(*in.scene), in.falloff, table_params<ConeParams>(params), in.seed);
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
