// SPDX-License-Identifier: Apache-2.0
// Voxel cone traced AO (docs/methods/cone.md): voxelization and the cone pass separately, the
// shape of the paper's Table III (time against resolution) and Table IV (time against triangle
// count), and quality against the ray-traced reference as counters (RMSE), so one run gives the
// numbers in BENCHMARKS.md. Run with --benchmark_filter=cone.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>

#include "ao/eval/metrics.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/methods/filters/bilateral.h"
#include "ao/methods/cone/cone.h"
#include "ao/reference/raytraced.h"
#include "bench_scenes.h"
#include "support/open_sheets.h"

namespace ao::bench {
namespace {

// A scene with its BVH (for the G-buffer), topology and G-buffers by size, built once.
struct ConeFixture {
  Scene scene;
  RayScene rays;
  std::vector<MeshClosure> closure;
  float r_max;
  std::map<std::pair<int, int>, GBuffer> gbuffers;

  explicit ConeFixture(Scene s) : scene(std::move(s)), rays(scene), closure(analyze_closure(scene)), r_max(0.1f * scene.bounds().diagonal()) {}
  const GBuffer& gbuffer(int w, int h) {
    auto it = gbuffers.find({w, h});
    if (it == gbuffers.end()) it = gbuffers.emplace(std::pair{w, h}, render_gbuffer(rays, framed(scene, w, h))).first;
    return it->second;
  }
};

// An open mesh on a ground quad, as bench/tools/open_sheets writes them.
Scene open_on_ground(Mesh m) {
  const Bounds3 b = m.bounds();
  const Vec3 c = b.center();
  const float e = b.diagonal();
  Scene s;
  s.name = "open";
  s.meshes = {std::move(m), make_quad({c.x - e, b.lo.y, c.z + e}, {c.x + e, b.lo.y, c.z + e}, {c.x + e, b.lo.y, c.z - e}, {c.x - e, b.lo.y, c.z - e})};
  validate_and_prepare(s);
  return s;
}

// `file` is a shared mesh (on a ground), "default", one of the open test meshes ("arch", "bowl",
// "open-box"), or a shared mesh alone: "NAME.off#closed" as it is, "NAME.off#cut" opened as a scan
// (bottom 10% cut off) or "NAME.off#holes" (holes of 3% of its diagonal).
ConeFixture* fixture(const std::string& file) {
  static std::map<std::string, std::unique_ptr<ConeFixture>> cache;
  auto it = cache.find(file);
  if (it != cache.end()) return it->second.get();
  std::unique_ptr<ConeFixture> f;
  const std::size_t hash = file.find('#');
  if (file == "default") {
    f = std::make_unique<ConeFixture>(make_builtin_scene("default"));
  } else if (file == "arch" || file == "bowl" || file == "open-box") {
    f = std::make_unique<ConeFixture>(
        open_on_ground(file == "arch" ? test::make_holed_arch() : file == "bowl" ? test::make_bowl() : test::make_open_box()));
  } else if (hash != std::string::npos) {
    const std::filesystem::path path = shared_meshes_dir() / file.substr(0, hash);
    if (std::filesystem::exists(path)) {
      const Mesh closed = load_scene_file(path).meshes.at(0);
      Scene s;
      s.name = file;
      const std::string how = file.substr(hash + 1);
      s.meshes = {how == "cut" ? test::cut_base(closed, 0.1f) : how == "holes" ? test::punch_holes(closed, 0.03f) : closed};
      validate_and_prepare(s);
      f = std::make_unique<ConeFixture>(std::move(s));
    }
  } else if (auto s = mesh_on_ground(file)) {
    f = std::make_unique<ConeFixture>(std::move(*s));
  }
  return cache.emplace(file, std::move(f)).first->second.get();
}

// What analyze_closure costs: boundary edges, holes, and for open meshes the winding-number
// hierarchy and the enclosure that classifies them.
void cone_closure(benchmark::State& state, const std::string& file) {
  ConeFixture* f = fixture(file);
  if (!f) return state.SkipWithError("../shared/data/meshes not found");
  for (auto _ : state) benchmark::DoNotOptimize(analyze_closure(f->scene));
}

// ConeContext frame after frame (`ao view`): the grids kept, the sides of the open meshes per
// pixel and the cone pass.
void cone_context_frame(benchmark::State& state, const std::string& file) {
  ConeFixture* f = fixture(file);
  if (!f) return state.SkipWithError("../shared/data/meshes not found");
  const GBuffer& g = f->gbuffer(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  ConeContext ctx(f->scene);
  const ConeParams p = cone_preset(ConeQuality::Medium);
  ctx.render(g, f->r_max, p, 1);
  double sides = 0;
  for (auto _ : state) sides += ctx.render(g, f->r_max, p, 1).sides_ms;
  state.counters["sides_ms"] = sides / static_cast<double>(state.iterations());
}

// Voxelization of a mesh into a world grid of columns x columns x depth_bits.
void cone_voxelize(benchmark::State& state, const std::string& file) {
  ConeFixture* f = fixture(file);
  if (!f) return state.SkipWithError("../shared/data/meshes not found");
  VoxelizeOptions o;
  o.columns = static_cast<int>(state.range(0));
  o.depth_bits = static_cast<int>(state.range(1));
  o.slab_thickness = f->r_max;
  VoxelStats stats;
  for (auto _ : state) benchmark::DoNotOptimize(voxelize_world(f->scene, f->closure, o, &stats));
  state.counters["Mtri/s"] = benchmark::Counter(static_cast<double>(f->scene.triangle_count()) * state.iterations() / 1e6, benchmark::Counter::kIsRate);
  state.counters["triangles"] = static_cast<double>(f->scene.triangle_count());
  state.counters["odd_columns"] = static_cast<double>(stats.odd_columns);
}

// The cone pass alone (grid built once) at width x height, preset from range(2).
void cone_trace(benchmark::State& state, const std::string& file) {
  ConeFixture* f = fixture(file);
  if (!f) return state.SkipWithError("../shared/data/meshes not found");
  const GBuffer& g = f->gbuffer(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const ConeParams p = cone_preset(static_cast<ConeQuality>(state.range(2))).resolved();
  const VoxelGrid grid = voxelize_world(f->scene, f->closure, p.voxelize_options(f->r_max));
  Image<float> v(g.width(), g.height());
  for (auto _ : state) compute_cone(g, grid, f->r_max, p, 1, v.view());
  std::size_t covered = 0;
  for (std::size_t i = 0; i < g.object_id.size(); ++i) covered += g.covered(i) ? 1 : 0;
  state.counters["Mpix/s"] = benchmark::Counter(static_cast<double>(covered) * state.iterations() / 1e6, benchmark::Counter::kIsRate);
  state.counters["covered"] = static_cast<double>(covered);
}

// The cone pass alone on the default scene at 640 x 360 (the size of `ao compare`): the per-pixel
// jitter off/on (range 0) and the cone count (range 1), to measure their cost as ratios in one run
// (--benchmark_enable_random_interleaving alternates them).
void cone_trace_variants(benchmark::State& state) {
  ConeFixture* f = fixture("default");
  const GBuffer& g = f->gbuffer(640, 360);
  ConeParams p = cone_preset(ConeQuality::Medium).resolved();
  p.jitter = state.range(0) != 0;
  p.cones = static_cast<int>(state.range(1));
  const VoxelGrid grid = voxelize_world(f->scene, f->closure, p.voxelize_options(f->r_max));
  Image<float> v(g.width(), g.height());
  for (auto _ : state) compute_cone(g, grid, f->r_max, p, 1, v.view());
}

// The cross-bilateral filter alone on the same image (range 0: taps).
void cone_filter(benchmark::State& state) {
  ConeFixture* f = fixture("default");
  const GBuffer& g = f->gbuffer(640, 360);
  ConeParams p = cone_preset(ConeQuality::Medium).resolved();
  const VoxelGrid grid = voxelize_world(f->scene, f->closure, p.voxelize_options(f->r_max));
  Image<float> v(g.width(), g.height());
  compute_cone(g, grid, f->r_max, p, 1, v.view());
  BilateralParams b;
  b.taps = static_cast<int>(state.range(0));
  for (auto _ : state) {
    Image<float> w = v;
    bilateral_filter(g, w, b);
    benchmark::DoNotOptimize(w);
  }
}

// The whole frame after the G-buffer: voxelization + cone pass (Tables III and IV).
void cone_frame(benchmark::State& state, const std::string& file) {
  ConeFixture* f = fixture(file);
  if (!f) return state.SkipWithError("../shared/data/meshes not found");
  const GBuffer& g = f->gbuffer(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const ConeParams p = cone_preset(ConeQuality::Medium);
  for (auto _ : state) benchmark::DoNotOptimize(render_cone(f->scene, f->closure, g, f->r_max, p, 1));
  state.counters["triangles"] = static_cast<double>(f->scene.triangle_count());
}

// Quality: RMSE against the ray-traced reference (step, R = R_max, 1024 rays, standard error
// ~0.01) at 320 x 240, as counters; args: preset, depth bits.
void cone_rmse(benchmark::State& state, const std::string& file) {
  ConeFixture* f = fixture(file);
  if (!f) return state.SkipWithError("../shared/data/meshes not found");
  const GBuffer& g = f->gbuffer(320, 240);
  static std::map<std::string, Image<float>> references;
  if (!references.count(file))
    references[file] = render_raytraced(f->rays, g, {Membership::Step, f->r_max}, {.samples = 1024}, 7).visibility;
  ConeParams p = cone_preset(static_cast<ConeQuality>(state.range(0)));
  p.depth_bits = static_cast<int>(state.range(1));
  ErrorMetrics m;
  for (auto _ : state) {
    const ConeResult r = render_cone(f->scene, f->closure, g, f->r_max, p, 1);
    m = compare_images(r.visibility, references[file], coverage_mask(g));
  }
  state.counters["rmse"] = m.rmse;
  state.counters["mean_signed"] = m.mean_signed;
}

constexpr int kLow = 0, kMedium = 1, kHigh = 2;

// Open meshes (docs/methods/cone.md, "Open meshes"): classification, voxelization and the whole
// cone call (every side's grid, the sides per pixel) against the closed scans they are cut from.
#define AO_CONE_OPEN(name, file)                                                                                            \
  BENCHMARK_CAPTURE(cone_closure, name, std::string(file))->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);   \
  BENCHMARK_CAPTURE(cone_voxelize, name, std::string(file))->Args({512, 128})->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5); \
  BENCHMARK_CAPTURE(cone_frame, name, std::string(file))->Args({640, 360})->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5)
AO_CONE_OPEN(dragon, "ChineseDragon-10kv.off#closed");
AO_CONE_OPEN(dragon_cut, "ChineseDragon-10kv.off#cut");
AO_CONE_OPEN(dragon_holes, "ChineseDragon-10kv.off#holes");
AO_CONE_OPEN(elephant, "elephant.off#closed");
AO_CONE_OPEN(elephant_cut, "elephant.off#cut");
AO_CONE_OPEN(elephant_holes, "elephant.off#holes");
AO_CONE_OPEN(arch, "arch");
AO_CONE_OPEN(bowl, "bowl");
AO_CONE_OPEN(open_box, "open-box");
AO_CONE_OPEN(default_scene, "default");
#undef AO_CONE_OPEN
BENCHMARK_CAPTURE(cone_context_frame, default_scene, std::string("default"))->Args({960, 540})->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);

BENCHMARK_CAPTURE(cone_voxelize, refined_elephant, std::string("refined_elephant.off"))
    ->Args({512, 256})->Args({512, 128})->Args({512, 512})->Args({512, 1024})->Args({256, 256})
    ->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);
BENCHMARK_CAPTURE(cone_trace, refined_elephant, std::string("refined_elephant.off"))
    ->Args({1024, 768, kMedium})->Args({1024, 768, kLow})->Args({1024, 768, kHigh})
    ->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);
BENCHMARK_CAPTURE(cone_trace, default_scene, std::string("default"))->Args({1024, 768, kMedium})->Args({960, 540, kMedium})->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);
BENCHMARK(cone_trace_variants)->Args({0, 6})->Args({1, 6})->Args({1, 16})->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);
BENCHMARK(cone_filter)->Arg(5)->Arg(7)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);
// Table III shape: one mesh, growing resolution.
BENCHMARK_CAPTURE(cone_frame, table3_refined_elephant, std::string("refined_elephant.off"))
    ->Args({640, 480})->Args({800, 600})->Args({1024, 768})->Args({1280, 960})->Args({1600, 1200})
    ->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);
// Table IV shape: fixed resolution, growing triangle count.
#define AO_CONE_TABLE4(name, file) \
  BENCHMARK_CAPTURE(cone_frame, table4_##name, std::string(file))->Args({1024, 768})->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5)
AO_CONE_TABLE4(pinion, "pinion.off");
AO_CONE_TABLE4(elephant, "elephant.off");
AO_CONE_TABLE4(cow, "cow.off");
AO_CONE_TABLE4(knot1, "knot1.off");
AO_CONE_TABLE4(turbine, "turbine.off");
AO_CONE_TABLE4(dragon, "ChineseDragon-10kv.off");
AO_CONE_TABLE4(fandisk_large, "fandisk_large.off");
AO_CONE_TABLE4(refined_elephant, "refined_elephant.off");
#undef AO_CONE_TABLE4
// Quality against the reference: presets at the paper's 128 bits, then depth bits at medium.
BENCHMARK_CAPTURE(cone_rmse, elephant, std::string("elephant.off"))
    ->Args({kLow, 128})->Args({kMedium, 128})->Args({kHigh, 128})->Args({kMedium, 256})->Args({kMedium, 512})
    ->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(cone_rmse, default_scene, std::string("default"))
    ->Args({kLow, 128})->Args({kMedium, 128})->Args({kHigh, 128})->Args({kMedium, 256})->Args({kMedium, 512})
    ->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace ao::bench
