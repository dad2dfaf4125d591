// SPDX-License-Identifier: Apache-2.0
// AO map baking: the histogram baker (McGraw & Sowers) against the ray-traced baker, as rates.
// The paper's Table 1 setting: 1024 x 1024 map, 512 and 1024 directions. Run with 2 threads:
//   ao_bench --benchmark_filter=Bake --benchmark_min_time=1 (taskset/--threads via TBB default).
#include <benchmark/benchmark.h>

#include <map>
#include <optional>

#include <tbb/global_control.h>

#include "ao/bake/histogram.h"
#include "ao/bake/raytraced_bake.h"
#include "ao/bake/texel_coverage.h"
#include "ao/io/mesh_io.h"
#include "ao/reference/triangle_pairs_internal.h"
#include "bench_scenes.h"

namespace ao::bench {
namespace {

struct BakeFixture {
  Scene scene;
  TexelCoverage coverage;
};

BakeFixture* uv_mesh(const std::string& file, int size) {
  static std::map<std::pair<std::string, int>, std::optional<BakeFixture>> cache;
  auto& f = cache[{file, size}];
  if (!f) {
    const std::filesystem::path path = shared_meshes_dir() / file;
    Scene s = std::filesystem::exists(path) ? load_scene_file(path) : stand_in_uv_scene(file);
    TexelCoverage c = compute_texel_coverage(s, size);
    f.emplace(BakeFixture{std::move(s), std::move(c)});
  }
  return &*f;
}

void histogram(benchmark::State& state, const std::string& file) {
  const int size = static_cast<int>(state.range(0)), dirs = static_cast<int>(state.range(1));
  BakeFixture* f = uv_mesh(file, size);
  if (!f) return state.SkipWithError("../shared/data/meshes not found");
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
  for (auto _ : state) benchmark::DoNotOptimize(bake_histogram(f->scene, f->coverage, {.directions = dirs}));
  state.counters["texels/s"] = benchmark::Counter(static_cast<double>(f->coverage.covered_texels) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["triangles"] = static_cast<double>(f->scene.triangle_count());
}

void raytraced(benchmark::State& state, const std::string& file) {
  const int size = static_cast<int>(state.range(0)), spp = static_cast<int>(state.range(1));
  BakeFixture* f = uv_mesh(file, size);
  if (!f) return state.SkipWithError("../shared/data/meshes not found");
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
  const RayScene rs(f->scene, bake_bvh_options(f->scene.triangle_count()));  // the BVH `ao bake` builds
  for (auto _ : state) benchmark::DoNotOptimize(bake_raytraced(rs, f->coverage, {.samples = spp}));
  const double texels = static_cast<double>(f->coverage.covered_texels) * state.iterations();
  state.counters["texels/s"] = benchmark::Counter(texels, benchmark::Counter::kIsRate);
  state.counters["rays/s"] = benchmark::Counter(texels * spp, benchmark::Counter::kIsRate);
}

void uv_coverage(benchmark::State& state, const std::string& file) {
  BakeFixture* f = uv_mesh(file, 1024);
  if (!f) return state.SkipWithError("../shared/data/meshes not found");
  for (auto _ : state) benchmark::DoNotOptimize(compute_texel_coverage(f->scene, 1024));
}

// The bake BVH's quads (reference/triangle_pairs.cpp): part of every bake's fixed cost.
void triangle_pairs(benchmark::State& state, const std::string& file) {
  BakeFixture* f = uv_mesh(file, 1024);
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
  for (auto _ : state) benchmark::DoNotOptimize(detail::pair_triangles(f->scene.meshes.front()));
  state.counters["triangles"] = static_cast<double>(f->scene.meshes.front().triangle_count());
}

BENCHMARK_CAPTURE(histogram, elephant, std::string("refined_elephant_uv.obj"))
    ->Args({1024, 128})->Args({1024, 256})->Args({1024, 512})->Args({1024, 1024})->Args({512, 512})
    ->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true);
BENCHMARK_CAPTURE(histogram, dragon, std::string("ChineseDragon-10kv_uv.obj"))
    ->Args({1024, 512})->Args({1024, 1024})->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true);
BENCHMARK_CAPTURE(raytraced, elephant, std::string("refined_elephant_uv.obj"))
    ->Args({512, 64})->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK_CAPTURE(uv_coverage, elephant, std::string("refined_elephant_uv.obj"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(triangle_pairs, elephant, std::string("refined_elephant_uv.obj"))->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace ao::bench
