// SPDX-License-Identifier: Apache-2.0
// Alchemy AO and its cross-bilateral filter: the AO pass only (G-buffer given), 1280x720, 12
// samples per pixel, 2 threads, the budget (8 ms and 3 ms). Inputs are built once outside
// the timed loops. Counters: Mpix/s (all pixels of the image) and Msamples/s (covered pixels x s).
#include <benchmark/benchmark.h>

#include <optional>

#include <tbb/global_control.h>

#include "ao/gbuffer/render_gbuffer.h"
#include "ao/methods/alchemy/alchemy.h"
#include "ao/methods/filters/bilateral.h"
#include "ao/reference/ray_scene.h"
#include "bench_scenes.h"

namespace ao::bench {
namespace {

constexpr int kWidth = 1280, kHeight = 720, kSamples = 12, kThreads = 2;

struct AlchemyFixture {
  Scene scene;
  GBuffer gbuffer;
  float radius;
  std::size_t covered = 0;

  explicit AlchemyFixture(Scene s) : scene(std::move(s)) {
    const RayScene rays(scene);
    gbuffer = render_gbuffer(rays, framed(scene, kWidth, kHeight));
    radius = 0.1f * scene.bounds().diagonal();  // the CLI's default R
    for (std::size_t i = 0; i < gbuffer.object_id.size(); ++i) covered += gbuffer.covered(i);
  }
};

AlchemyFixture* demo() {
  static AlchemyFixture f(make_builtin_scene("default"));
  return &f;
}

AlchemyFixture* elephant() {
  static std::optional<AlchemyFixture> f = [] {
    auto s = mesh_on_ground("refined_elephant.off");
    return s ? std::optional<AlchemyFixture>(std::in_place, std::move(*s)) : std::nullopt;
  }();
  return f ? &*f : nullptr;
}

void set_counters(benchmark::State& state, const AlchemyFixture& f, int samples) {
  const double pixels = static_cast<double>(kWidth) * kHeight * state.iterations();
  state.counters["Mpix/s"] = benchmark::Counter(pixels / 1e6, benchmark::Counter::kIsRate);
  if (samples > 0)
    state.counters["Msamples/s"] =
        benchmark::Counter(static_cast<double>(f.covered) * samples * state.iterations() / 1e6, benchmark::Counter::kIsRate);
}

// Eq. 10 alone (filter off).
void alchemy_estimator(benchmark::State& state, AlchemyFixture* f) {
  if (!f) return state.SkipWithError("../shared/data/meshes not found");
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, kThreads);
  AlchemyParams p;
  p.samples = static_cast<int>(state.range(0));
  p.filter = false;
  for (auto _ : state) benchmark::DoNotOptimize(render_alchemy(f->gbuffer, p, f->radius, 1));
  set_counters(state, *f, p.samples);
}

// The filter alone on a fixed noisy image: two 13-tap passes.
void bilateral(benchmark::State& state, AlchemyFixture* f) {
  if (!f) return state.SkipWithError("../shared/data/meshes not found");
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, kThreads);
  AlchemyParams p;
  p.filter = false;
  const Image<float> noisy = render_alchemy(f->gbuffer, p, f->radius, 1).visibility;
  const BilateralParams bp;
  Image<float> work = noisy;
  for (auto _ : state) {
    state.PauseTiming();
    work = noisy;
    state.ResumeTiming();
    bilateral_filter(f->gbuffer, work, bp);
    benchmark::DoNotOptimize(work.data());
  }
  set_counters(state, *f, 0);
}

// What `ao render --method alchemy` runs: eq. 10, then the filter (plus the copy kept as "unfiltered").
void alchemy_filtered(benchmark::State& state, AlchemyFixture* f) {
  if (!f) return state.SkipWithError("../shared/data/meshes not found");
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, kThreads);
  AlchemyParams p;
  for (auto _ : state) benchmark::DoNotOptimize(render_alchemy(f->gbuffer, p, f->radius, 1));
  set_counters(state, *f, p.samples);
}

BENCHMARK_CAPTURE(alchemy_estimator, default_scene, demo())->Arg(kSamples)->Arg(4)->Arg(32)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(1.0)->Repetitions(3)->ReportAggregatesOnly();
BENCHMARK_CAPTURE(bilateral, default_scene, demo())->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(1.0)->Repetitions(3)->ReportAggregatesOnly();
BENCHMARK_CAPTURE(alchemy_filtered, default_scene, demo())->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(1.0)->Repetitions(3)->ReportAggregatesOnly();
BENCHMARK_CAPTURE(alchemy_estimator, elephant_on_ground, elephant())->Arg(kSamples)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(1.0)->Repetitions(3)->ReportAggregatesOnly();
BENCHMARK_CAPTURE(bilateral, elephant_on_ground, elephant())->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(1.0)->Repetitions(3)->ReportAggregatesOnly();

}  // namespace
}  // namespace ao::bench
