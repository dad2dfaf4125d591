// SPDX-License-Identifier: Apache-2.0
// Screen-space AO passes (containment, volumetric, transfer, gtao) and the 4x4 depth-aware box filter,
// AO pass only: the G-buffer of the built-in default scene at 1280x720 is rendered once outside
// the timed loops. 12 samples per pixel (VAO fig. 12's count), R = 0.1 x scene diagonal (the
// CLI's default). Thread count: whatever TBB is given (run with taskset -c 0,1 for 2 threads).
// The CPU column is the main thread's CPU time: with 2 busy threads, about the wall time on 2 free
// cores (the machine is shared; real time is inflated by other jobs).
#include <benchmark/benchmark.h>

#include <array>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "ao/gbuffer/render_gbuffer.h"
#include "ao/methods/characteristic.h"
#include "ao/methods/containment/containment.h"
#include "ao/methods/containment/containment_kernel_internal.h"
#include "ao/methods/gtao/gtao.h"
#include "ao/methods/filters/interleave.h"
#include "ao/methods/screen_space_internal.h"
#include "ao/methods/transfer/transfer.h"
#include "ao/methods/transfer/transfer_internal.h"
#include "ao/methods/volumetric/volumetric.h"
#include "ao/reference/direct_light.h"
#include "ao/simd/depth_plane.h"
#include "bench_scenes.h"

namespace ao::bench {
namespace {

constexpr int kWidth = 1280, kHeight = 720, kSamples = 12;

// AO_BENCH_RADIUS_SCALE=s scales R (default 1): how much of a pass's time is cache misses that
// grow with the screen-space footprint of the samples (see BENCHMARKS.md).
float radius_scale() {
  const char* s = std::getenv("AO_BENCH_RADIUS_SCALE");
  return s ? std::strtof(s, nullptr) : 1.0f;
}

struct Fixture {
  Scene scene = make_builtin_scene("default");
  RayScene rays{scene};
  GBuffer g = render_gbuffer(rays, framed(scene, kWidth, kHeight));
  float radius = radius_scale() * 0.1f * scene.bounds().diagonal();
};

Fixture& demo() {
  static Fixture f;
  return f;
}

void rate(benchmark::State& state) {
  state.counters["Mpix/s"] = benchmark::Counter(static_cast<double>(kWidth) * kHeight * state.iterations() / 1e6, benchmark::Counter::kIsRate);
}

// Args: filter (0/1), ray_steps m (1 = eq. 5's end point; the default is 3).
void containment(benchmark::State& state) {
  Fixture& f = demo();
  ContainmentParams p{.samples = kSamples, .ray_steps = static_cast<int>(state.range(1))};
  p.interleave.filter = state.range(0) != 0;
  for (auto _ : state) benchmark::DoNotOptimize(containment_ao(f.g, {Membership::Step, f.radius}, p, 1));
  rate(state);
}

void volumetric(benchmark::State& state) {
  Fixture& f = demo();
  VolumetricParams p{.samples = kSamples};
  p.interleave.filter = state.range(0) != 0;
  for (auto _ : state) benchmark::DoNotOptimize(volumetric_ao(f.g, f.radius, p, 1));
  rate(state);
}

void transfer(benchmark::State& state) {
  Fixture& f = demo();
  TransferParams p{.samples = kSamples, .ray_steps = static_cast<int>(state.range(1))};
  p.interleave.filter = state.range(0) != 0;
  // A renderer's use: buffers kept from frame to frame (the first call allocates them).
  TransferBuffers buffers;
  for (auto _ : state) benchmark::DoNotOptimize(transfer_ao(buffers, f.g, {Membership::Step, f.radius}, p, 1).luminance.data());
  rate(state);
}

// The radiance mode (reflectance=radiance, docs/methods/transfer.md) with a sun's direct-light
// pass made once outside the loop; filtered, m = 2 (the default): compare with transfer/1/2.
void transfer_radiance(benchmark::State& state) {
  Fixture& f = demo();
  GBuffer g = f.g;
  g.direct = render_direct_light(f.rays, g, Sun{normalize(Vec3{-1.0f, 0.6f, 0.5f}), kPi});
  TransferParams p{.samples = kSamples, .reflectance = TransferReflectance::Radiance};
  TransferBuffers buffers;
  for (auto _ : state) benchmark::DoNotOptimize(transfer_ao(buffers, g, {Membership::Step, f.radius}, p, 1).luminance.data());
  rate(state);
}

// GTAO at its defaults (2 slices x 2 sides x 8 steps = 32 depth samples per pixel); arg: filter (0/1).
void gtao(benchmark::State& state) {
  Fixture& f = demo();
  GtaoParams p;
  p.interleave.filter = state.range(0) != 0;
  for (auto _ : state) benchmark::DoNotOptimize(gtao_ao(f.g, f.radius, p, 1).visibility.data());
  rate(state);
}

// The contiguous depth plane (GBuffer::depth of every pixel) each depth-reading pass builds once
// from the positions and ids: what the G-buffer no longer stores costs the passes this much.
void depth_plane_build(benchmark::State& state) {
  Fixture& f = demo();
  Image<float> plane;
  for (auto _ : state) {
    depth_plane(f.g, plane);
    benchmark::DoNotOptimize(plane.data());
  }
  rate(state);
}

void box_filter(benchmark::State& state) {
  Fixture& f = demo();
  const Image<float> v(kWidth, kHeight, 0.5f);
  for (auto _ : state) benchmark::DoNotOptimize(depth_aware_box_filter(v, f.g, 0.25f * f.radius));
  rate(state);
}

void box_filter_rgb(benchmark::State& state) {
  Fixture& f = demo();
  const Image<Vec3> v(kWidth, kHeight, Vec3{0.5f, 0.5f, 0.5f});
  for (auto _ : state) benchmark::DoNotOptimize(depth_aware_box_filter(v, f.g, 0.25f * f.radius));
  rate(state);
}

// What transfer filters: W's three channels and O as planes, one depth test per tap for all four.
void box_filter_planes4(benchmark::State& state) {
  Fixture& f = demo();
  std::array<Image<float>, 4> v;
  for (auto& p : v) p = Image<float>(kWidth, kHeight, 0.5f);
  Image<float>* planes[] = {&v[0], &v[1], &v[2], &v[3]};
  for (auto _ : state) {
    depth_aware_box_filter_planes(planes, f.g, 0.25f * f.radius);
    benchmark::DoNotOptimize(v[0].data());
  }
  rate(state);
}

// The floor under the depth-buffer methods: N depth tests per covered pixel and nothing else (a
// point at distance R in one of N fixed directions of the pixel's tangent frame, projected, one
// depth gather, one compare, a count: simd::count_open_rays with m = 1 on rows of covered pixels
// prepared outside the timed loop), over the same G-buffer and threads. At their defaults transfer
// (m = 2) makes 24 such tests per pixel and containment (m = 3) 36, plus their per-pixel setup,
// sample offsets and accumulation; this says how much of their time the tests alone need.
// Counter: ns per test of one pixel (CPU time of all threads / tests).
void depth_test_floor(benchmark::State& state) {
  Fixture& f = demo();
  const int tests = static_cast<int>(state.range(0));
  std::vector<float> dx(static_cast<std::size_t>(tests)), dy(dx.size()), dz(dx.size());
  for (int t = 0; t < tests; ++t) {  // a spiral over the upper hemisphere, radius R
    const float zc = 1.0f - (static_cast<float>(t) + 0.5f) / static_cast<float>(tests), rc = std::sqrt(1.0f - zc * zc);
    const float a = 2.39996f * static_cast<float>(t);
    dx[static_cast<std::size_t>(t)] = f.radius * rc * std::cos(a), dy[static_cast<std::size_t>(t)] = f.radius * rc * std::sin(a);
    dz[static_cast<std::size_t>(t)] = f.radius * zc;
  }
  const DepthBufferCharacteristic ch(f.g);
  const simd::DepthPlane plane = simd_depth_plane(ch);
  const simd::TestPoints points{dx.data(), dy.data(), dz.data(), tests};
  const simd::Rotations16 rot = simd_rotations(interleave_rotations(1, true));
  std::vector<simd::CoveredPixels> rows(static_cast<std::size_t>(kHeight));
  std::size_t covered = 0;
  for (int y = 0; y < kHeight; ++y) {
    simd::load_covered_pixels(rows[static_cast<std::size_t>(y)], f.g, y, 0, kWidth, rot, 0.0f, true);
    covered += static_cast<std::size_t>(rows[static_cast<std::size_t>(y)].count);
  }
  std::atomic<long long> total{0};
  for (auto _ : state) {
    tbb::parallel_for(tbb::blocked_range<int>(0, kHeight, 8), [&](const tbb::blocked_range<int>& r) {
      simd::AlignedVector<float> open(static_cast<std::size_t>(simd::padded(kWidth)));
      long long sum = 0;
      for (int y = r.begin(); y < r.end(); ++y) {
        const simd::CoveredPixels& row = rows[static_cast<std::size_t>(y)];
        simd::count_open_rays(row, plane, points, 1, -kInfinity, open.data());
        for (int k = 0; k < row.count; ++k) sum += static_cast<long long>(open[static_cast<std::size_t>(k)]);
      }
      total += sum;
    });
  }
  benchmark::DoNotOptimize(total.load());
  state.counters["ns/test"] = benchmark::Counter(static_cast<double>(state.iterations()) * static_cast<double>(covered) * tests,
                                                 benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["Mpix/s"] = benchmark::Counter(static_cast<double>(kWidth) * kHeight * state.iterations() / 1e6, benchmark::Counter::kIsRate);
}
BENCHMARK(depth_test_floor)->Arg(12)->Arg(24)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

// Arg: filter on (1) / off (0); transfer's second arg is m (tests per ray).
BENCHMARK(containment)->Args({0, 1})->Args({1, 1})->Args({0, 3})->Args({1, 3})->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(volumetric)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(gtao)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(transfer)->Args({0, 1})->Args({0, 2})->Args({1, 1})->Args({1, 2})->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(transfer_radiance)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(depth_plane_build)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(box_filter)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(box_filter_rgb)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(box_filter_planes4)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

}  // namespace
}  // namespace ao::bench
