// SPDX-License-Identifier: Apache-2.0
// The GPU backend (src/ao/gpu/) against the CPU backend, method by method, on the same G-buffer:
// the built-in default scene at 640x360 (cone: closed meshes, below), each method at its defaults,
// R = 0.1 x the scene's diagonal. gpu/<method> runs the method on a G-buffer already on the device
// and reads its images back (what `ao render --device gpu` does per image), with the GPU time of
// each pass (timestamp queries) as counters "<pass> ms"; cpu/<method> runs the registry's CPU
// kernel on the same G-buffer. gbuffer/gpu rasterizes the G-buffer, gbuffer/cpu ray-traces it.
//
// Here the device is Mesa's llvmpipe, which runs the shaders on the CPU's cores (the "GPU" times
// are CPU times of llvmpipe's threads); on a GPU machine run the same binary with AO_BENCH_GPU=1 to
// take the first hardware EGL device. Without a usable GL (or AO_GPU=OFF) the gpu/ benchmarks
// report the device's error and skip.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "ao/gbuffer/render_gbuffer.h"
#include "ao/registry/methods_gpu.h"
#include "ao/methods/cone/voxelize_gpu.h"
#include "ao/registry/registry.h"
#include "bench_scenes.h"

namespace ao::bench {
namespace {

constexpr int kWidth = 640, kHeight = 360;

// A scene of closed meshes for cone, which the GPU voxelizes itself by the paper's parity (a scene
// with open surfaces gets the CPU's grid, uploaded): a box for the ground, a sphere, a turned box,
// a torus.
Scene closed_scene() {
  Scene s;
  s.name = "closed meshes";
  s.meshes.push_back(make_box({-3.0f, -0.3f, -3.0f}, {3.0f, 0.0f, 3.0f}));
  s.meshes.push_back(make_sphere({-0.8f, 0.7f, 0.2f}, 0.7f));
  s.meshes.push_back(make_box({0.4f, 0.0f, -0.9f}, {1.4f, 1.2f, 0.1f}, {0.8f, 0.8f, 0.8f}, 30.0f));
  s.meshes.push_back(make_torus({0.6f, 0.25f, 1.3f}, 0.6f, 0.25f));
  validate_and_prepare(s);
  return s;
}

struct Fixture {
  Scene scene;
  RayScene rays{scene};
  GBuffer g;
  float radius;
  std::optional<GpuDevice> device;
  std::optional<GpuScene> gpu_scene;
  std::optional<GpuGBuffer> gpu_g;
  std::string error;  // why there is no device

  explicit Fixture(Scene s)
      : scene(std::move(s)), g(render_gbuffer(rays, framed(scene, kWidth, kHeight))), radius(0.1f * scene.bounds().diagonal()) {
    try {
      device = GpuDevice::open({.software = std::getenv("AO_BENCH_GPU") == nullptr});
      gpu_scene = GpuScene::upload(*device, scene);
      gpu_g = GpuGBuffer::upload(*device, g);
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
};

Fixture& fixture(const std::string& method) {
  static Fixture demo(make_builtin_scene("default")), closed(closed_scene());
  return method == "cone" ? closed : demo;
}

nlohmann::json defaults(const std::string& method) {
  nlohmann::json p = find_method(method).default_params();
  if (method == "cone") p["open_meshes"] = "parity";  // the same voxels on both backends (closed meshes)
  return p;
}

void pixels_rate(benchmark::State& state) {
  state.counters["Mpix/s"] = benchmark::Counter(static_cast<double>(kWidth) * kHeight * state.iterations() / 1e6, benchmark::Counter::kIsRate);
}

void gpu_method(benchmark::State& state, const std::string& method) {
  Fixture& f = fixture(method);
  if (!f.device) return state.SkipWithError(f.error.c_str());
  const MethodParams params = find_method(method).decode(defaults(method));
  const GpuMethodInput in{*f.gpu_g, &*f.gpu_scene, {Membership::Step, f.radius}, 1};
  std::map<std::string, double> ms;
  run_gpu_method(*f.device, in, params);  // compiles the shaders (llvmpipe: tens of ms), untimed
  for (auto _ : state) {
    const GpuMethodOutput out = run_gpu_method(*f.device, in, params);
    for (const GpuPassTime& p : out.passes) ms[p.name] += p.ms;
    benchmark::DoNotOptimize(out.output.visibility.data());
  }
  for (const auto& [name, total] : ms) state.counters[name + " ms"] = total / static_cast<double>(state.iterations());
  state.SetLabel(f.device->renderer());
  pixels_rate(state);
}

void cpu_method(benchmark::State& state, const std::string& method) {
  Fixture& f = fixture(method);
  const MethodParams params = find_method(method).decode(defaults(method));
  MethodCache cache;  // cone keeps its grid, as the GPU does between calls
  for (auto _ : state) {
    const MethodOutput out = run_method({f.g, &f.rays, {Membership::Step, f.radius}, 1, {}, nullptr, &cache}, params);
    benchmark::DoNotOptimize(out.visibility.data());
  }
  pixels_rate(state);
}

void gbuffer_gpu(benchmark::State& state) {
  Fixture& f = fixture("default");
  if (!f.device) return state.SkipWithError(f.error.c_str());
  double ms = 0;
  GpuGBuffer::rasterize(*f.device, *f.gpu_scene, f.g.camera);  // compiles the shaders, untimed
  for (auto _ : state) {
    const GpuGBuffer g = GpuGBuffer::rasterize(*f.device, *f.gpu_scene, f.g.camera);
    ms += g.passes().front().ms;
  }
  state.counters["gbuffer ms"] = ms / static_cast<double>(state.iterations());
  state.SetLabel(f.device->renderer());
  pixels_rate(state);
}

void gbuffer_cpu(benchmark::State& state) {
  Fixture& f = fixture("default");
  GBuffer g;
  for (auto _ : state) {
    render_gbuffer(f.rays, f.g.camera, g);
    benchmark::DoNotOptimize(g.position.data());
  }
  pixels_rate(state);
}

// The cone grid alone, built anew every iteration (the GPU caches it per scene between calls).
void voxelize_gpu(benchmark::State& state) {
  Fixture& f = fixture("cone");
  if (!f.device) return state.SkipWithError(f.error.c_str());
  VoxelizeOptions o;
  o.open_meshes = OpenMeshes::Parity;
  gpu_voxelize_world(*f.device, *f.gpu_scene, o);  // compiles the shaders, untimed
  for (auto _ : state) benchmark::DoNotOptimize(gpu_voxelize_world(*f.device, *f.gpu_scene, o).bits.data());
  state.SetLabel(f.device->renderer());
}

void voxelize_cpu(benchmark::State& state) {
  Fixture& f = fixture("cone");
  VoxelizeOptions o;
  o.open_meshes = OpenMeshes::Parity;
  const std::vector<MeshClosure> closure = analyze_closure(f.scene);
  for (auto _ : state) benchmark::DoNotOptimize(voxelize_world(f.scene, closure, o).bits.data());
}

const int kRegistered = [] {
  for (const char* m : {"containment", "volumetric", "transfer", "alchemy", "gtao", "cone"}) {
    benchmark::RegisterBenchmark((std::string("gpu/") + m).c_str(), gpu_method, std::string(m))->Unit(benchmark::kMillisecond)->UseRealTime();
    benchmark::RegisterBenchmark((std::string("cpu/") + m).c_str(), cpu_method, std::string(m))->Unit(benchmark::kMillisecond)->UseRealTime();
  }
  benchmark::RegisterBenchmark("gbuffer/gpu", gbuffer_gpu)->Unit(benchmark::kMillisecond)->UseRealTime();
  benchmark::RegisterBenchmark("gbuffer/cpu", gbuffer_cpu)->Unit(benchmark::kMillisecond)->UseRealTime();
  benchmark::RegisterBenchmark("voxelize/gpu", voxelize_gpu)->Unit(benchmark::kMillisecond)->UseRealTime();
  benchmark::RegisterBenchmark("voxelize/cpu", voxelize_cpu)->Unit(benchmark::kMillisecond)->UseRealTime();
  return 0;
}();

}  // namespace
}  // namespace ao::bench
