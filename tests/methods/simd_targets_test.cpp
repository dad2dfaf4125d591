// SPDX-License-Identifier: Apache-2.0
// The SIMD kernels on every target this machine runs (ao/simd/target.h): each target can be
// chosen, and the methods' images agree between targets. Targets with FMA (AVX3_DL, AVX3, AVX2)
// compute the same operations with the same roundings, so they agree bit for bit; SSE4, SSSE3 and
// the fallback (EMU128, or SCALAR under GCC before 12.3) have no fused multiply-add, so a
// multiply-add rounds twice there, which moves a test point by an ulp or so: a depth test decided
// within that distance of the surface can flip (tolerances below).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <string>

#include "ao/bake/histogram.h"
#include "ao/bake/texel_coverage.h"
#include "ao/core/error.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/methods/filters/bilateral.h"
#include "ao/methods/filters/interleave.h"
#include "ao/reference/raytraced.h"
#include "ao/registry/registry.h"
#include "ao/scene/procedural.h"
#include "ao/simd/target.h"

namespace ao {
namespace {

// Restores the process's target (a per-target run of the suite restricts it) when a test ends.
class TargetGuard {
 public:
  TargetGuard() : saved_(simd_target()) {}
  ~TargetGuard() { set_simd_target(saved_ == simd_targets().front() ? "" : saved_); }

 private:
  std::string saved_;
};

bool has_fma(const std::string& target) { return target == "AVX3_DL" || target == "AVX3" || target == "AVX2"; }

TEST(SimdTargets, EveryTargetCanBeChosenAndUnknownNamesAreRefused) {
  const TargetGuard guard;
  const std::vector<std::string> targets = simd_targets();
  ASSERT_FALSE(targets.empty());
  EXPECT_TRUE(targets.back() == "EMU128" || targets.back() == "SCALAR") << "the portable fallback is always there: " << targets.back();
  for (const std::string& t : targets) {
    set_simd_target(t);
    EXPECT_EQ(simd_target(), t);
    EXPECT_EQ(simd_targets(), targets) << "the list does not depend on the choice";
  }
  set_simd_target("");
  EXPECT_EQ(simd_target(), targets.front()) << "\"\" returns to the best";
  try {
    set_simd_target("AVX1024");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("AVX1024"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(targets.front()), std::string::npos) << "names the choices: " << e.what();
  }
}

struct Differences {
  double fraction = 0;  // of the pixels that differ at all
  double beyond = 0;    // of the pixels that differ by more than kRounding
  double mean = 0;      // mean |a - b| over all pixels
  float max = 0;        // largest |a - b|
};

// What rounding alone can do to a V in [0, 1] computed through a hundred or so float operations
// (each off by up to 2^-24 relative): 1e-5. A depth or voxel test decided within such a rounding
// of its threshold can flip, and move V by a whole test (1/12 of a screen-space pixel's rays, a
// sphere's prism by a voxel): such pixels may be at most 0.1% of the image, by at most 0.25.
constexpr float kRounding = 1e-5f;

Differences differences(const Image<float>& a, const Image<float>& b) {
  Differences d;
  std::size_t differ = 0, beyond = 0;
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const float e = std::abs(a[i] - b[i]);
    differ += a[i] != b[i] ? 1 : 0;
    beyond += e > kRounding ? 1 : 0;
    sum += e;
    d.max = std::max(d.max, e);
  }
  d.fraction = static_cast<double>(differ) / static_cast<double>(a.size());
  d.beyond = static_cast<double>(beyond) / static_cast<double>(a.size());
  d.mean = sum / static_cast<double>(a.size());
  return d;
}

// Every method of the registry at its defaults on the default scene (160 x 90), each target against
// the best one. Targets with FMA agree bit for bit, and so do the targets without it among
// themselves; between the two groups the images differ by rounding (kRounding), and by a flipped
// test in at most 0.1% of the pixels. Measured here: containment and transfer bit for bit on every
// target, the others in 5-30% of the pixels by at most 1.0e-6 (BENCHMARKS.md, "Portable build against -march=native").
TEST(SimdTargets, MethodImagesAgreeBetweenTargets) {
  const TargetGuard guard;
  const Scene scene = make_builtin_scene("default");
  const RayScene rays(scene);
  Camera c = *scene.preferred_view;
  c.width = 160, c.height = 90;
  const GBuffer g = render_gbuffer(rays, c);
  const Falloff falloff{Membership::Step, 0.1f * scene.bounds().diagonal()};
  const std::vector<std::string> targets = simd_targets();
  for (const MethodInfo& m : all_methods()) {
    if (m.ground_truth) continue;  // Embree's own dispatch, not the kernel layer
    // At the defaults, and with the second depth layer where the method has one (its own kernels).
    std::vector<nlohmann::json> variants{m.default_params()};
    if (variants.front().contains("layers")) variants.push_back(m.canonical_params({{"layers", 2}}));
    for (const nlohmann::json& params : variants) {
    auto run = [&](const std::string& target) {
      set_simd_target(target);
      return run_method(MethodInput{g, &rays, falloff, 5, {}, &scene.analytic}, m.decode(params)).visibility;
    };
    std::map<bool, Image<float>> first;  // the first image of each group: with FMA, without
    const Image<float> best = run(targets.front());
    for (const std::string& t : targets) {
      const Image<float> image = t == targets.front() ? best : run(t);
      const Differences d = differences(best, image);
      std::printf("%-12s %-8s vs %-8s: %.4f%% of pixels differ, %.4f%% by more than %g, max %.4g, mean %.3g\n", std::string(m.name).c_str(),
                  t.c_str(), targets.front().c_str(), 100 * d.fraction, 100 * d.beyond, kRounding, d.max, d.mean);
      const auto [group, fresh] = first.try_emplace(has_fma(t), image);
      if (!fresh) {
        EXPECT_EQ(differences(group->second, image).fraction, 0.0) << m.name << " on " << t << ": as the other targets of its group";
      }
      EXPECT_LE(d.beyond, 0.001) << m.name << " on " << t;
      EXPECT_LE(d.max, 0.25f) << m.name << " on " << t;
      EXPECT_LE(d.mean, 1e-4) << m.name << " on " << t;
    }
    }
  }
}

// The 4x4 box filter only adds and divides: every target gives the same bits, for floats and RGB.
// The bilateral filter's taps are multiply-adds: the targets with FMA agree bit for bit, the
// others within the rounding of its weights (kRounding; the values are in [0, 1]).
TEST(SimdTargets, FiltersAgreeBetweenTargets) {
  const TargetGuard guard;
  const Scene scene = make_builtin_scene("default");
  const RayScene rays(scene);
  Camera c = *scene.preferred_view;
  c.width = 123, c.height = 77;  // odd sizes: partial vectors at every row's end on every target
  const GBuffer g = render_gbuffer(rays, c);
  Image<float> noisy(c.width, c.height);
  Image<Vec3> rgb(c.width, c.height);
  for (std::size_t i = 0; i < noisy.size(); ++i) {
    noisy[i] = static_cast<float>((i * 2654435761u) % 1000) / 1000.0f;
    rgb[i] = Vec3{noisy[i], 1.0f - noisy[i], 0.5f * noisy[i]};
  }
  const std::vector<std::string> targets = simd_targets();
  auto filters = [&](const std::string& target) {
    set_simd_target(target);
    std::map<std::string, Image<float>> out;
    out["box"] = depth_aware_box_filter(noisy, g, 0.3f);
    const Image<Vec3> box_rgb = depth_aware_box_filter(rgb, g, 0.3f);
    Image<float> flat(c.width * 3, c.height);
    std::copy(&box_rgb.data()->x, &box_rgb.data()->x + flat.size(), flat.data());
    out["box rgb"] = flat;
    Image<float> b = noisy;
    bilateral_filter(g, b, BilateralParams{});
    out["bilateral"] = b;
    return out;
  };
  const auto best = filters(targets.front());
  for (std::size_t k = 1; k < targets.size(); ++k) {
    const auto other = filters(targets[k]);
    for (const auto& [name, image] : best) {
      const Differences d = differences(image, other.at(name));
      if (name != "bilateral" || (has_fma(targets[k]) && has_fma(targets.front()))) {
        EXPECT_EQ(d.fraction, 0.0) << name << " on " << targets[k] << " (max difference " << d.max << ")";
      } else {
        EXPECT_LE(d.max, kRounding) << name << " on " << targets[k];
      }
    }
  }
}

// The G-buffer's and the outside-in baker's kernels are scalar code compiled once per target
// without contraction (ao/gbuffer/gbuffer_kernel.cpp, histogram.cpp): every target gives the same bits.
// The G-buffer's rays, the reference's directions (no fused multiply-add in either) and the
// histogram bake's integer counts: the same bits on every target, with or without FMA.
TEST(SimdTargets, GBufferReferenceAndHistogramBakeAreTheSameBitsOnEveryTarget) {
  const TargetGuard guard;
  Scene scene = make_builtin_scene("default");
  // Planar UVs from x and z over the scene's box (overlapping charts: the baker only warns).
  const Bounds3 box = scene.bounds();
  const Vec3 size = box.hi - box.lo;
  for (Mesh& m : scene.meshes) {
    m.uvs.clear();
    for (const Vec3& p : m.positions) m.uvs.push_back(Vec2{(p.x - box.lo.x) / size.x, (p.z - box.lo.z) / size.z});
  }
  const RayScene rays(scene);
  Camera c = *scene.preferred_view;
  c.width = 123, c.height = 77;
  const TexelCoverage coverage = compute_texel_coverage(scene, 48);
  const std::vector<std::string> targets = simd_targets();
  auto same = [](const auto& a, const auto& b) { return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(*a.data())) == 0; };
  set_simd_target(targets.front());
  const GBuffer best = render_gbuffer(rays, c);
  const BakeResult best_bake = bake_histogram(scene, coverage, {.directions = 24});
  const Falloff falloff{Membership::Step, 0.1f * length(size)};
  const RaytracedImage best_reference = render_raytraced(rays, best, falloff, {.samples = 24}, 7);
  ASSERT_GT(best_bake.fragments, 1000u) << "the bake sees the scene";
  ASSERT_GT(std::count(best.object_id.data(), best.object_id.data() + best.object_id.size(), 0u), 0) << "background too";
  for (std::size_t k = 1; k < targets.size(); ++k) {
    set_simd_target(targets[k]);
    const GBuffer g = render_gbuffer(rays, c);
    EXPECT_TRUE(same(g.position, best.position) && same(g.normal, best.normal) && same(g.albedo, best.albedo) && same(g.uv, best.uv) &&
                same(g.object_id, best.object_id) && same(g.primitive_id, best.primitive_id))
        << "G-buffer on " << targets[k];
    const RaytracedImage reference = render_raytraced(rays, best, falloff, {.samples = 24}, 7);
    EXPECT_TRUE(same(reference.visibility, best_reference.visibility) && same(reference.std_error, best_reference.std_error))
        << "reference on " << targets[k];
    EXPECT_TRUE(same(bake_histogram(scene, coverage, {.directions = 24}).visibility, best_bake.visibility)) << "histogram bake on " << targets[k];
  }
}

}  // namespace
}  // namespace ao
