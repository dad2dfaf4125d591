// SPDX-License-Identifier: Apache-2.0
// run_gpu_method (methods_gpu.h): the method's GPU path, chosen by its parameter struct.
#include "ao/registry/methods_gpu.h"

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/gpu/run_internal.h"
#include "ao/methods/alchemy/alchemy_gpu_internal.h"
#include "ao/methods/cone/cone_gpu_internal.h"
#include "ao/methods/containment/containment_gpu_internal.h"
#include "ao/methods/gtao/gtao_gpu_internal.h"
#include "ao/methods/transfer/transfer_gpu_internal.h"
#include "ao/methods/volumetric/volumetric_gpu_internal.h"
#include "ao/reference/ray_scene.h"

namespace ao {

GpuMethodOutput run_gpu_method(GpuDevice& device, const GpuMethodInput& in, const MethodParams& params) {
  using namespace gpu_detail;
  check_gpu_method(params);
  Context& c = Access::context(device);
  if (Access::textures(in.gbuffer).context.get() != &c) throw InputError("--device gpu: the G-buffer was made on another device");
  const std::string_view method = method_of(params).name;
  c.make_current();
  Run r{c, Access::textures(in.gbuffer), {}};
  GpuMethodOutput out;
  out.output = std::visit(
      [&](const auto& p) -> MethodOutput {
        if constexpr (requires { run_gpu(r, in, p); }) return run_gpu(r, in, p);
        else throw std::logic_error("check_gpu_method let through a method without a GPU path");
      },
      params);
  c.check("running " + std::string(method));
  out.passes = c.resolve(r.passes);
  out.renderer = c.renderer;
  nlohmann::json ms = nlohmann::json::object();
  for (const GpuPassTime& p : out.passes) ms[p.name] = ms.value(p.name, 0.0) + p.ms;
  if (!out.output.stats->is_object()) out.output.stats = nlohmann::json::object();
  out.output.stats["device"] = c.renderer;
  out.output.stats["gpu_ms"] = ms;
  for (const auto& [name, passes] : r.reported_ms) {
    double sum = 0;
    for (const std::string& pass : passes) sum += ms.value(pass, 0.0);
    out.output.stats[name] = sum;
  }
  return out;
}

GpuMethodOutput run_gpu_method(GpuDevice& device, const MethodInput& in, const MethodParams& params) {
  check_gpu_method(params);
  const GpuGBuffer g = GpuGBuffer::upload(device, in.gbuffer);
  std::optional<GpuScene> scene;
  const Scene* cpu_scene = in.scene ? in.scene : in.rays ? &in.rays->scene() : nullptr;
  if (method_of(params).needs_scene && cpu_scene) scene = GpuScene::upload(device, *cpu_scene);
  GpuMethodOutput out = run_gpu_method(device, GpuMethodInput{g, scene ? &*scene : nullptr, in.falloff, in.seed}, params);
  out.passes.insert(out.passes.begin(), g.passes().begin(), g.passes().end());
  out.output.stats["gpu_ms"]["upload"] = g.passes().front().ms;
  return out;
}

}  // namespace ao
