// SPDX-License-Identifier: Apache-2.0
// G-buffer and ray-traced ground truth against an independent bare Embree loop (bare_embree.h)
// on the same scene, camera, R and ray count: the ratios BENCHMARKS.md reports. Run them
// interleaved (--benchmark_enable_random_interleaving=true) so that both contenders see the same
// machine load. Without ../shared the built-in default scene stands in for the meshes.
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <memory>

#include "ao/gbuffer/render_gbuffer.h"
#include "ao/reference/direct_light.h"
#include "ao/reference/packets_internal.h"
#include "ao/reference/ray_offset.h"
#include "ao/reference/raytraced.h"
#include "bare_embree.h"
#include "bench_scenes.h"

namespace ao::bench {
namespace {

constexpr int kWidth = 1280, kHeight = 720, kSamples = 64;

struct Fixture {
  Scene scene;
  RayScene rays;
  GBuffer gbuffer;
  Falloff falloff;
  bare::Loop bare;
  std::vector<bare::Hit> hits;
  float bare_offset;

  // R = 0.1 x the diagonal of the objects of interest: the meshes, not the ground quad added
  // last (`ao render`'s default, docs/methods/raytraced.md).
  Fixture(Scene s, bool ground_last)
      : scene(std::move(s)), rays(scene), gbuffer(render_gbuffer(rays, framed(scene, kWidth, kHeight))), bare(scene) {
    Bounds3 b;
    for (std::size_t i = 0; i + (ground_last ? 1 : 0) < scene.meshes.size(); ++i) b.extend(scene.meshes[i].bounds());
    falloff = {Membership::Step, 0.1f * b.diagonal()};
    bare.primary(gbuffer.camera, hits);
    bare_offset = 1e-6f * scene.bounds().diagonal();  // tiny, as a minimal program would pick
  }
};

Fixture* fixture(const std::string& name) {
  static std::map<std::string, std::unique_ptr<Fixture>> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return it->second.get();
  std::unique_ptr<Fixture> f;
  if (name == "default") {
    f = std::make_unique<Fixture>(make_builtin_scene("default"), false);
  } else if (auto s = mesh_on_ground(name)) {
    f = std::make_unique<Fixture>(std::move(*s), true);
  } else {  // ../shared absent: the built-in scene stands in
    return fixture("default");
  }
  return cache.emplace(name, std::move(f)).first->second.get();
}

const char* kElephant = "refined_elephant.off";
const char* kDragon = "ChineseDragon-10kv.off";

void set_rate(benchmark::State& state, double rays_per_iteration) {
  state.counters["Mrays/s"] = benchmark::Counter(rays_per_iteration * static_cast<double>(state.iterations()) / 1e6, benchmark::Counter::kIsRate);
}

// ao's G-buffer, rendered into a reused GBuffer as a renderer drawing frame after frame would:
// the channels `ao render --method raytraced` renders (no albedo, no UVs), or with `full` all.
void gbuffer_ao(benchmark::State& state, const char* mesh, bool full) {
  Fixture* f = fixture(mesh);
  const Camera cam = f->gbuffer.camera;
  const GBufferOptions options{.albedo = full, .uv = full};
  GBuffer g;
  render_gbuffer(f->rays, cam, options, g);
  for (auto _ : state) {
    render_gbuffer(f->rays, cam, options, g);
    benchmark::DoNotOptimize(g.position.data());
  }
  set_rate(state, static_cast<double>(cam.width) * cam.height);
}

// The deep G-buffer's second layer (render_second_layer) at the automatic separation R/4: one more
// ray per covered pixel, from the visible surface on; what layers=2 adds to a screen-space method.
void second_layer(benchmark::State& state, const char* mesh) {
  Fixture* f = fixture(mesh);
  GBuffer g = f->gbuffer;
  const float separation = 0.25f * f->falloff.radius;
  for (auto _ : state) {
    render_second_layer(f->rays, g, separation);
    benchmark::DoNotOptimize(g.second_depth.data());
  }
  set_rate(state, static_cast<double>(g.width()) * g.height());
}

// The bare loop's primary pass over the same camera (hit point and geometric normal per pixel).
void gbuffer_bare(benchmark::State& state, const char* mesh) {
  Fixture* f = fixture(mesh);
  const Camera cam = f->gbuffer.camera;
  std::vector<bare::Hit> hits;
  f->bare.primary(cam, hits);
  for (auto _ : state) {
    f->bare.primary(cam, hits);
    benchmark::DoNotOptimize(hits.data());
  }
  set_rate(state, static_cast<double>(cam.width) * cam.height);
}

// ao's ground truth, step membership, 64 rays per covered pixel, seed 1.
void reference_ao(benchmark::State& state, const char* mesh) {
  Fixture* f = fixture(mesh);
  std::uint64_t rays = 0;
  double sum_v = 0;
  for (auto _ : state) {
    const RaytracedImage img = render_raytraced(f->rays, f->gbuffer, f->falloff, {.samples = kSamples}, 1);
    rays = img.rays;
    sum_v = 0;
    for (std::size_t i = 0; i < img.visibility.size(); ++i) sum_v += f->gbuffer.covered(i) ? img.visibility[i] : 0.0;
  }
  set_rate(state, static_cast<double>(rays));
  state.counters["mean_V"] = sum_v * kSamples / static_cast<double>(rays);
}

// The bare loop's AO pass: the same pixels, R and ray count.
void reference_bare(benchmark::State& state, const char* mesh) {
  Fixture* f = fixture(mesh);
  std::uint64_t rays = 0, open = 0;
  for (auto _ : state) open = f->bare.ambient_occlusion(f->hits, kWidth, kHeight, f->falloff.radius, kSamples, f->bare_offset, &rays);
  set_rate(state, static_cast<double>(rays));
  state.counters["mean_V"] = static_cast<double>(open) / static_cast<double>(rays);
}

// The sun's direct-light pass (`ao render --sun`): one shadow ray per covered pixel facing the
// sun, the sun of docs/methods/transfer.md's picture. Mrays/s counts the rays traced.
void direct_light(benchmark::State& state, const char* mesh) {
  Fixture* f = fixture(mesh);
  const Sun sun{normalize(Vec3{-1.0f, 0.6f, 0.5f}), kPi};
  const Vec3 l = f->gbuffer.camera.basis().to_local(sun.direction);  // camera space, as the G-buffer's normals
  double rays = 0;
  for (std::size_t i = 0; i < f->gbuffer.object_id.size(); ++i) rays += f->gbuffer.covered(i) && dot(f->gbuffer.normal[i], l) > 0;
  for (auto _ : state) benchmark::DoNotOptimize(render_direct_light(f->rays, f->gbuffer, sun).data());
  set_rate(state, rays);
}

// Does Sobol pay for itself? Error per pixel at 64 rays of the reference (Sobol, shifted per
// pixel) and of plain random directions (the bare loop's PCG), at the same points about the same
// (geometric) normals, against the reference at 1024 rays; 640x360. Counters: RMSE over covered
// pixels of each, and their ratio (random / Sobol). At equal time the ratio is scaled by the
// square root of the time ratio of the two AO passes (BENCHMARKS.md).
void sampling_error(benchmark::State& state, const char* mesh) {
  Fixture* f = fixture(mesh);
  Camera cam = f->gbuffer.camera;
  cam.width = 640;
  cam.height = 360;
  const GBuffer g = render_gbuffer(f->rays, cam, GBufferOptions{.normal = SurfaceNormal::Geometric});
  std::vector<bare::Hit> hits(g.object_id.size());
  const Frame basis = cam.basis();
  for (std::size_t i = 0; i < hits.size(); ++i) {
    hits[i].valid = g.covered(i);
    const Vec3 p = basis.to_world(g.position[i]) + cam.eye, n = basis.to_world(g.normal[i]);
    hits[i].p = {p.x, p.y, p.z};
    hits[i].n = {n.x, n.y, n.z};
  }
  double rmse_sobol = 0, rmse_random = 0;
  for (auto _ : state) {
    const RaytracedImage truth = render_raytraced(f->rays, g, f->falloff, {.samples = 1024}, 99);
    const RaytracedImage sobol = render_raytraced(f->rays, g, f->falloff, {.samples = kSamples}, 1);
    std::vector<float> random;
    std::uint64_t rays = 0;
    f->bare.ambient_occlusion(hits, cam.width, cam.height, f->falloff.radius, kSamples, ray_offset_distance(max_abs_coordinate(cam.eye) * 2), &rays,
                              &random);
    double es = 0, er = 0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < hits.size(); ++i) {
      if (!hits[i].valid) continue;
      ++n;
      es += std::pow(sobol.visibility[i] - truth.visibility[i], 2.0);
      er += std::pow(random[i] - truth.visibility[i], 2.0);
    }
    rmse_sobol = std::sqrt(es / static_cast<double>(n));
    rmse_random = std::sqrt(er / static_cast<double>(n));
  }
  state.counters["rmse_sobol"] = rmse_sobol;
  state.counters["rmse_random"] = rmse_random;
  state.counters["random_over_sobol"] = rmse_random / rmse_sobol;
}

BENCHMARK_CAPTURE(sampling_error, elephant_on_ground, kElephant)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(sampling_error, dragon_on_ground, kDragon)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(direct_light, default_scene, "default")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_CAPTURE(gbuffer_ao, default_scene, "default", false)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(1.0);
BENCHMARK_CAPTURE(gbuffer_ao, default_scene_all_channels, "default", true)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(1.0);
BENCHMARK_CAPTURE(second_layer, default_scene, "default")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_CAPTURE(second_layer, dragon_on_ground, kDragon)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_CAPTURE(gbuffer_bare, default_scene, "default")->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(1.0);
BENCHMARK_CAPTURE(gbuffer_ao, elephant_on_ground, kElephant, false)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(1.0);
BENCHMARK_CAPTURE(gbuffer_ao, elephant_on_ground_all_channels, kElephant, true)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(1.0);
BENCHMARK_CAPTURE(gbuffer_bare, elephant_on_ground, kElephant)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(1.0);
BENCHMARK_CAPTURE(gbuffer_ao, dragon_on_ground, kDragon, false)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(1.0);
BENCHMARK_CAPTURE(gbuffer_ao, dragon_on_ground_all_channels, kDragon, true)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(1.0);
BENCHMARK_CAPTURE(gbuffer_bare, dragon_on_ground, kDragon)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(1.0);
BENCHMARK_CAPTURE(reference_ao, elephant_on_ground_64spp, kElephant)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK_CAPTURE(reference_bare, elephant_on_ground_64spp, kElephant)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK_CAPTURE(reference_ao, dragon_on_ground_64spp, kDragon)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK_CAPTURE(reference_bare, dragon_on_ground_64spp, kDragon)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK_CAPTURE(reference_ao, default_scene_64spp, "default")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK_CAPTURE(reference_bare, default_scene_64spp, "default")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

}  // namespace
}  // namespace ao::bench

BENCHMARK_MAIN();
