// G-buffer and ray-traced ground truth, against a minimal Embree loop that traces the same rays
// and does nothing else: the limit the reference is measured against (BENCHMARKS.md).
#include <benchmark/benchmark.h>

#include <array>

#include "ao/core/parallel.h"
#include "ao/core/sampling.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/reference/direct_light.h"
#include "ao/reference/packets_internal.h"
#include "ao/reference/raytraced.h"
#include "bench_scenes.h"

namespace ao::bench {
namespace {

constexpr int kWidth = 1280, kHeight = 720, kSamples = 64;

struct Fixture {
  Scene scene;
  RayScene rays;
  GBuffer gbuffer;
  Falloff falloff;

  explicit Fixture(Scene s) : scene(std::move(s)), rays(scene), gbuffer(render_gbuffer(rays, framed(scene, kWidth, kHeight))) {
    falloff = {Membership::Step, 0.1f * scene.bounds().diagonal()};
  }
};

Fixture* elephant() {
  static std::optional<Fixture> f = [] {
    auto s = mesh_on_ground("refined_elephant.off");
    return s ? std::optional<Fixture>(std::in_place, std::move(*s)) : std::nullopt;
  }();
  return f ? &*f : nullptr;
}

Fixture* demo() {
  static Fixture f(make_builtin_scene("default"));
  return &f;
}

void gbuffer(benchmark::State& state, Fixture* f) {
  if (!f) return state.SkipWithError("../shared/data/meshes not found");
  const Camera cam = f->gbuffer.camera;
  GBuffer g;  // reused frame to frame, as a renderer would; the first call allocates
  render_gbuffer(f->rays, cam, g);
  for (auto _ : state) {
    render_gbuffer(f->rays, cam, g);
    benchmark::DoNotOptimize(g.depth.data());
  }
  state.counters["Mrays/s"] = benchmark::Counter(static_cast<double>(cam.width) * cam.height * state.iterations() / 1e6, benchmark::Counter::kIsRate);
}

// What both minimal loops trace from pixel (x, y): the reference's origin (offset along the normal),
// tangent frame and sample-set seed (seed 1, as the `raytraced` benchmark), so all three trace the
// same rays.
struct PixelRays {
  Vec3 origin;
  Frame frame;
  std::uint32_t seed;
};
PixelRays pixel_rays(const GBuffer& g, const Frame& basis, float offset, int x, int y) {
  const Vec3 n = basis.to_world(g.normal(x, y));
  return {basis.to_world(g.position(x, y)) + g.camera.eye + n * offset, Frame::from_normal(n), pixel_seed(1, x, y)};
}

// The limit: for every covered pixel, the same 64 cosine-weighted directions the reference uses
// (same seed, same sequence), 16-wide occlusion packets, a counter of hits. No accumulation of
// statistics, no early exit, nothing written.
void minimal_loop(benchmark::State& state, Fixture* f) {
  if (!f) return state.SkipWithError("../shared/data/meshes not found");
  const GBuffer& g = f->gbuffer;
  const Frame basis = g.camera.basis();
  const float offset = f->rays.self_intersection_offset(), R = f->falloff.radius;
  std::uint64_t rays = 0;
  for (auto _ : state) {
    std::atomic<std::uint64_t> hits{0};
    parallel_for_tiles(g.width(), g.height(), 16, [&](const Tile& t) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      alignas(64) RTCRay16 ray;
      alignas(64) std::array<int, 16> valid;
      valid.fill(-1);
      std::uint64_t local = 0;
      for (int y = t.y0; y < t.y1; ++y)
        for (int x = t.x0; x < t.x1; ++x) {
          if (!g.covered(x, y)) continue;
          const auto [o, frame, seed] = pixel_rays(g, basis, offset, x, y);
          for (int first = 0; first < kSamples; first += 16) {
            for (int k = 0; k < 16; ++k)
              detail::set_ray(ray, k, o, frame.to_world(cosine_hemisphere(sobol_owen_2d(static_cast<std::uint32_t>(first + k), seed))), R);
            rtcOccluded16(valid.data(), f->rays.handle(), &ctx, &ray);
            for (int k = 0; k < 16; ++k) local += ray.tfar[k] < 0;
          }
        }
      hits += local;
    });
    benchmark::DoNotOptimize(hits.load());
  }
  for (std::size_t i = 0; i < g.coverage.size(); ++i) rays += g.coverage[i] ? kSamples : 0;
  state.counters["Mrays/s"] = benchmark::Counter(static_cast<double>(rays) * state.iterations() / 1e6, benchmark::Counter::kIsRate);
}

// The same rays one at a time (rtcOccluded1): what the packets are measured against.
void minimal_loop_single_rays(benchmark::State& state, Fixture* f) {
  if (!f) return state.SkipWithError("../shared/data/meshes not found");
  const GBuffer& g = f->gbuffer;
  const Frame basis = g.camera.basis();
  const float offset = f->rays.self_intersection_offset(), R = f->falloff.radius;
  std::uint64_t rays = 0;
  for (auto _ : state) {
    std::atomic<std::uint64_t> hits{0};
    parallel_for_tiles(g.width(), g.height(), 16, [&](const Tile& t) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      std::uint64_t local = 0;
      for (int y = t.y0; y < t.y1; ++y)
        for (int x = t.x0; x < t.x1; ++x) {
          if (!g.covered(x, y)) continue;
          const auto [o, frame, seed] = pixel_rays(g, basis, offset, x, y);
          for (int i = 0; i < kSamples; ++i) {
            const Vec3 d = frame.to_world(cosine_hemisphere(sobol_owen_2d(static_cast<std::uint32_t>(i), seed)));
            RTCRay ray{o.x, o.y, o.z, 0.0f, d.x, d.y, d.z, 0.0f, R, ~0u, 0, 0};
            rtcOccluded1(f->rays.handle(), &ctx, &ray);
            local += ray.tfar < 0;
          }
        }
      hits += local;
    });
    benchmark::DoNotOptimize(hits.load());
  }
  for (std::size_t i = 0; i < g.coverage.size(); ++i) rays += g.coverage[i] ? kSamples : 0;
  state.counters["Mrays/s"] = benchmark::Counter(static_cast<double>(rays) * state.iterations() / 1e6, benchmark::Counter::kIsRate);
}

void raytraced(benchmark::State& state, Fixture* f) {
  if (!f) return state.SkipWithError("../shared/data/meshes not found");
  std::uint64_t rays = 0;
  for (auto _ : state) {
    const auto img = render_raytraced(f->rays, f->gbuffer, f->falloff, {.samples = kSamples}, 1);
    rays += img.rays;
  }
  state.counters["Mrays/s"] = benchmark::Counter(static_cast<double>(rays) / 1e6, benchmark::Counter::kIsRate);
}

// The sun's direct-light pass (`ao render --sun`): one shadow ray per covered pixel facing the
// sun, the sun of docs/methods/transfer.md's picture. Mrays/s counts the rays traced.
void direct_light(benchmark::State& state, Fixture* f) {
  if (!f) return state.SkipWithError("../shared/data/meshes not found");
  const Sun sun{normalize(Vec3{-1.0f, 0.6f, 0.5f}), kPi};
  const Vec3 l = f->gbuffer.camera.basis().to_local(sun.direction);  // camera space, as the G-buffer's normals
  double rays = 0;
  for (std::size_t i = 0; i < f->gbuffer.coverage.size(); ++i) rays += f->gbuffer.coverage[i] && dot(f->gbuffer.normal[i], l) > 0;
  for (auto _ : state) benchmark::DoNotOptimize(render_direct_light(f->rays, f->gbuffer, sun).data());
  state.counters["Mrays/s"] = benchmark::Counter(rays * state.iterations() / 1e6, benchmark::Counter::kIsRate);
}

BENCHMARK_CAPTURE(direct_light, default_scene, demo())->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_CAPTURE(gbuffer, default_scene, demo())->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_CAPTURE(gbuffer, elephant_on_ground, elephant())->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_CAPTURE(minimal_loop, elephant_on_ground_64spp, elephant())->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK_CAPTURE(minimal_loop_single_rays, elephant_on_ground_64spp, elephant())->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK_CAPTURE(raytraced, elephant_on_ground_64spp, elephant())->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK_CAPTURE(minimal_loop, default_scene_64spp, demo())->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK_CAPTURE(raytraced, default_scene_64spp, demo())->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

}  // namespace
}  // namespace ao::bench

BENCHMARK_MAIN();
