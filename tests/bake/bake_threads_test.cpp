// SPDX-License-Identifier: Apache-2.0
// Every bake gives the same bits at any thread count, run after run: the ray-traced map with and
// without the filter (and its bent normals), high to low with and without the filter, per-vertex
// AO and the histogram map, each at 1, 2 and 5 threads, three times, compared byte for byte. Between
// runs the pool threads are left in mixed floating-point modes (flush-to-zero on some, not on
// others), as other work in a process may leave them: a kernel whose results depended on the mode a
// thread happened to be in (the filter's underflowing weights did) would differ from run to run.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <thread>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <xmmintrin.h>

#include "ao/bake/denoise.h"
#include "ao/bake/high_to_low.h"
#include "ao/bake/histogram.h"
#include "ao/bake/raytraced_bake.h"
#include "ao/bake/texel_coverage.h"
#include "ao/scene/procedural.h"

namespace ao {
namespace {

constexpr float kPi = 3.14159265358979f;

// A lat-long sphere of radius r(theta, phi) at `centre`, with UVs u = phi / 2 pi, v = 1 - theta / pi
// when `uvs`, counter-clockwise seen from outside; seam and pole vertices are exact copies.
Mesh sphere(int segments, int rings, Vec3 centre, const std::function<float(float, float)>& r, bool uvs) {
  Mesh m;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      const float theta = kPi * static_cast<float>(i) / static_cast<float>(rings);
      const float phi = 2 * kPi * static_cast<float>(j % segments) / static_cast<float>(segments);  // the seam's column repeats column 0
      const Vec3 d{std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)};
      m.positions.push_back(centre + (i == 0 || i == rings ? Vec3{0, i == 0 ? 1.0f : -1.0f, 0} : d) * r(theta, phi));
      if (uvs) m.uvs.push_back({static_cast<float>(j) / static_cast<float>(segments), 1.0f - static_cast<float>(i) / static_cast<float>(rings)});
    }
  const auto id = [&](int i, int j) { return static_cast<std::uint32_t>(i * (segments + 1) + j); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const std::uint32_t a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      m.indices.insert(m.indices.end(), {a, b, c, a, c, d});
    }
  return m;
}

float round_unit(float, float) { return 1.0f; }
float bumpy(float theta, float phi) { return 1.0f + 0.1f * std::sin(8 * phi) * std::sin(8 * theta); }

Scene prepared(std::vector<Mesh> meshes, const char* name) {
  Scene s;
  s.name = name;
  s.meshes = std::move(meshes);
  validate_and_prepare(s);
  return s;
}

// The low sphere resting on a floor slab without UVs (it occludes only), so the map has contact
// shadows, creases between facets and open texels.
Scene low_scene() { return prepared({sphere(24, 12, {0, 1, 0}, round_unit, true), make_box({-3, -0.2f, -3}, {3, 0, 3})}, "low"); }

// Leaves TBB's threads in mixed floating-point modes: flush-to-zero and denormals-are-zero on every
// other thread that picks up a task, the IEEE default on the rest.
void scramble_thread_modes() {
  const std::thread::id caller = std::this_thread::get_id();
  tbb::parallel_for(0, 256, [&](int i) {
    if (std::this_thread::get_id() == caller) return;  // the caller's mode is the caller's business
    const bool flush = (std::hash<std::thread::id>{}(std::this_thread::get_id()) + static_cast<std::size_t>(i / 64)) % 2 == 0;
    _mm_setcsr(flush ? (_mm_getcsr() | 0x8040u) : (_mm_getcsr() & ~0x8040u));
    volatile double spin = 0;
    for (int k = 0; k < 2000; ++k) spin = spin + k;
  });
}

template <class T>
std::vector<unsigned char> bytes_of(const T* data, std::size_t count) {
  std::vector<unsigned char> b(count * sizeof(T));
  std::memcpy(b.data(), data, b.size());
  return b;
}

std::vector<unsigned char> bytes_of(const BakeResult& r) {
  std::vector<unsigned char> b = bytes_of(r.visibility.data(), r.visibility.size());
  if (!r.bent_normal.empty()) {
    const std::vector<unsigned char> n = bytes_of(r.bent_normal.data(), r.bent_normal.size());
    b.insert(b.end(), n.begin(), n.end());
  }
  return b;
}

// Runs `bake` three times at each of 1, 2 and 5 threads, scrambling the threads' modes before each
// run, and expects every run's bytes to equal the first.
void expect_same_bits_at_any_thread_count(const char* what, const std::function<std::vector<unsigned char>()>& bake) {
  std::vector<unsigned char> first;
  for (const std::size_t threads : {1u, 2u, 5u})
    for (int run = 0; run < 3; ++run) {
      const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      scramble_thread_modes();
      const std::vector<unsigned char> b = bake();
      if (first.empty()) {
        first = b;
        ASSERT_FALSE(first.empty()) << what;
        continue;
      }
      EXPECT_TRUE(b == first) << what << ": run " << run << " at " << threads << " threads differs from the first run at 1 thread";
    }
}

// The filter's result does not depend on the floating-point mode of the thread that runs it: two
// texels one apart on one flat chart, V = 0 and V = 1, each with a measured variance such that the
// second pass's value term puts the neighbour's weight at exp(-95) ~ 5e-42, a denormal (the first
// pass's, with k_g = 1.5 against k = 2, at exp(-169), below every float: the guide is the raw map
// and its variance the texels' own). Flushed to zero, texel 0 stays exactly 0; in the IEEE default
// it would take a denormal's worth of its neighbour. The
// filter fixes its own mode, so both calls give the same bits (they differed when it ran in
// whatever mode the pool thread was left in).
TEST(BakeThreads, DenoisingDoesNotDependOnTheThreadsFloatingPointMode) {
  Mesh quad = make_quad({0, 0, 1}, {2, 0, 1}, {2, 0, 0}, {0, 0, 0});
  quad.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const Scene s = prepared({quad}, "strip");
  const TexelCoverage cov = compute_texel_coverage(s, 2, 1);
  ASSERT_EQ(cov.covered_texels, 2u);
  TexelGuides guides(cov.mask);
  guides.position[guides.slot(0, 0)] = {0.5f, 0, 0.5f};
  guides.position[guides.slot(1, 0)] = {1.5f, 0, 0.5f};
  guides.normal[guides.slot(0, 0)] = guides.normal[guides.slot(1, 0)] = {0, 1, 0};
  // 0.5 dV^2 / (2^2 (var_0 + var_1 + 0.01^2)) = 95 for dV = 1 (denoise.h, the second pass).
  guides.variance[guides.slot(0, 0)] = guides.variance[guides.slot(1, 0)] = 0.5f * (0.5f / (4.0f * 95.0f) - 1e-4f);
  const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);  // the filter runs on this thread
  const unsigned mode = _mm_getcsr();
  std::array<float, 2> result[2];
  for (int flush = 0; flush < 2; ++flush) {
    _mm_setcsr(flush ? (mode | 0x8040u) : (mode & ~0x8040u));
    Image<float> v(2, 1, 0.0f);
    v(1, 0) = 1.0f;
    denoise_map(v, cov.mask, cov, guides, 1.0f);
    result[flush] = {v(0, 0), v(1, 0)};
  }
  _mm_setcsr(mode);
  EXPECT_EQ(std::memcmp(result[0].data(), result[1].data(), sizeof(result[0])), 0) << result[0][0] << " / " << result[1][0];
  EXPECT_EQ(result[0][0], 0.0f);
  EXPECT_EQ(result[0][1], 1.0f);
}

TEST(BakeThreads, RaytracedMapsAreTheSameBitsAtAnyThreadCount) {
  const Scene s = low_scene();
  const TexelCoverage cov = compute_texel_coverage(s, 96);
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  expect_same_bits_at_any_thread_count("map", [&] { return bytes_of(bake_raytraced(rs, cov, {.samples = 32, .bent_normals = true})); });
  expect_same_bits_at_any_thread_count("denoised map", [&] { return bytes_of(bake_raytraced(rs, cov, {.samples = 32, .denoise = 1.0f})); });
  expect_same_bits_at_any_thread_count("denoised map, linear falloff", [&] {
    return bytes_of(bake_raytraced(rs, cov, {.samples = 24, .max_distance = 0.8f, .membership = Membership::Linear, .denoise = 2.0f}));
  });
}

TEST(BakeThreads, HighToLowIsTheSameBitsAtAnyThreadCount) {
  const Scene low = prepared({sphere(24, 12, {0, 0, 0}, round_unit, true)}, "low");
  const Scene high = prepared({sphere(96, 48, {0, 0, 0}, bumpy, false)}, "high");
  const RayScene high_rays(high);
  const TexelCoverage cov = compute_texel_coverage(low, 64);
  HighToLowParams p;
  p.ao.samples = 32;
  p.cage_extrusion = 0.2f;
  const CagePositions cage = extrude_cage(low, *p.cage_extrusion);
  expect_same_bits_at_any_thread_count("high to low", [&] { return bytes_of(bake_high_to_low(low, cov, cage, high_rays, high_rays, p)); });
  p.ao.denoise = 0.75f;
  p.ao.bent_normals = true;
  expect_same_bits_at_any_thread_count("denoised high to low", [&] { return bytes_of(bake_high_to_low(low, cov, cage, high_rays, high_rays, p)); });
}

TEST(BakeThreads, PerVertexAndHistogramAreTheSameBitsAtAnyThreadCount) {
  const Scene s = low_scene();
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  expect_same_bits_at_any_thread_count("per vertex", [&] {
    const std::vector<float> v = bake_vertices_raytraced(rs, {.samples = 32});
    return bytes_of(v.data(), v.size());
  });
  const TexelCoverage cov = compute_texel_coverage(s, 48);
  expect_same_bits_at_any_thread_count("histogram", [&] { return bytes_of(bake_histogram(s, cov, {.directions = 64})); });
}

}  // namespace
}  // namespace ao
