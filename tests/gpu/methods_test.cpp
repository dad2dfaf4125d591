// SPDX-License-Identifier: Apache-2.0
// The methods on the GPU against the CPU kernels on the same G-buffer (uploaded), with the same
// parameters, seed, sample sets and rotations; against the ray-traced reference; and their
// refusals of what the GPU backend does not implement.
//
// The tolerance of the agreement tests: at most 2.5% of the pixels may differ from the CPU's by
// more than 1e-5, and the mean |difference| stays below 2e-4. Both backends evaluate the same
// formulas on the same inputs in float, in a different order and with multiply-adds fused in other
// places (GCC contracts the CPU kernels, Mesa's compiler the shaders), so a continuous result
// differs by float roundings: measured at most 2e-6 (alchemy), 2.4e-7 for the others. Where a
// discrete decision sits within a rounding of its threshold -- a depth test, a pixel or column
// index, or cone's tangent frame of a wall whose world normal has z = +-1e-8 (Duff et al.'s frame
// flips with the sign of n.z; one ulp of the normal moves the CPU's own result from 0.404 to 0.334
// at box-room's pixel 42,13, which is the GPU's) -- a sample, or a cone, comes out otherwise; the
// 4x4 filter or the 5-tap bilateral spreads it to 16-25 pixels, and a cone of 6 moves the mean
// |difference| of a 96 x 64 image by about (1/6) / 6144 = 3e-5. Measured: none for the
// screen-space methods, 1-3 such pixels for cone (0.6% of the image after its filter, mean 4e-5);
// the bounds allow about 6 (a CPU without AVX-512 runs other CPU code paths, rounded otherwise).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>

#include "ao/core/error.h"
#include "ao/eval/metrics.h"
#include "ao/registry/methods_gpu.h"
#include "ao/reference/direct_light.h"
#include "ao/reference/reference.h"
#include "gpu/gpu_support.h"
#include "support/errors.h"
#include "support/open_sheets.h"
#include "support/scenes.h"

namespace ao {
namespace {

using test::gpu_device;
using test::gpu_fixture;

// The agreement rule above, for one image.
void expect_agreement(const Image<float>& gpu, const Image<float>& cpu, const std::string& what) {
  ASSERT_EQ(gpu.width(), cpu.width()) << what;
  ASSERT_EQ(gpu.height(), cpu.height()) << what;
  double sum = 0, worst = 0;
  std::size_t apart = 0, worst_at = 0;
  for (std::size_t i = 0; i < cpu.size(); ++i) {
    const double e = std::abs(static_cast<double>(gpu[i]) - cpu[i]);
    ASSERT_TRUE(std::isfinite(gpu[i])) << what << " pixel " << i;
    sum += e;
    apart += e > 1e-5 ? 1 : 0;
    if (e > worst) worst = e, worst_at = i;
  }
  const double mean = sum / static_cast<double>(cpu.size());
  EXPECT_LE(static_cast<double>(apart), 0.025 * static_cast<double>(cpu.size()))
      << what << ": " << apart << " pixels differ by more than 1e-5; worst " << worst << " at pixel " << worst_at % cpu.width() << ","
      << worst_at / cpu.width();
  EXPECT_LE(mean, 2e-4) << what << ": mean |difference| " << mean;
}

// Parameters every scene can run: cone's paper voxelization (the GPU's; the CPU's slabs for open
// surfaces are not implemented on it).
nlohmann::json gpu_params(const std::string& method) {
  nlohmann::json p = find_method(method).default_params();
  if (method == "cone") p["open_meshes"] = "parity";
  return p;
}

class GpuMethodAgreement : public ::testing::TestWithParam<std::tuple<std::string, std::string>> {};

TEST_P(GpuMethodAgreement, AgreesWithTheCpuKernelOnTheSameGBuffer) {
  const auto& [method, scene] = GetParam();
  const test::GpuFixture f = gpu_fixture(scene, 96, 64);
  const nlohmann::json params = gpu_params(method);
  const MethodInput in{f.g, f.rays.get(), {Membership::Linear, 0.5f * f.radius}, 7, {}, &f.scene.analytic};
  const MethodOutput cpu = run_method(in, find_method(method).decode(params));
  const GpuMethodOutput gpu = run_gpu_method(gpu_device(), in, find_method(method).decode(params));
  expect_agreement(gpu.output.visibility, cpu.visibility, method + " on " + scene);
  ASSERT_EQ(gpu.output.color.empty(), cpu.color.empty());
  for (const auto& [name, image] : cpu.extras) {
    ASSERT_TRUE(gpu.output.extras.contains(name)) << name;
    expect_agreement(gpu.output.extras.at(name), image, method + " " + name);
  }
  // The passes: the upload first, then the method's own (and its filter), each timed.
  ASSERT_GE(gpu.passes.size(), 2u);
  EXPECT_EQ(gpu.passes.front().name, "upload");
  for (const GpuPassTime& p : gpu.passes) EXPECT_GE(p.ms, 0.0) << p.name;
  EXPECT_EQ(gpu.renderer, gpu_device().renderer());
  EXPECT_EQ(gpu.output.stats["device"], gpu_device().renderer());
  EXPECT_TRUE(gpu.output.stats["gpu_ms"].contains(method == "cone" ? "voxelize" : method));
}

// Cone with its default open-mesh handling on open meshes seen from both sides (the ground under an
// arch, the ground inside a dome through its window, the ground beyond a leaf's rim;
// tests/support/open_sheets.h): the GPU traces each side's grid, voxelized by the CPU, over that
// side's pixels, so it agrees with the CPU as on closed scenes, with the same grids.
TEST(GpuCone, OpenMeshesTraceEachSidesGridAsTheCpuDoes) {
  for (const auto& [what, object] :
       {std::pair{"arch", ao::test::make_holed_arch()}, std::pair{"dome", ao::test::make_dome()}, std::pair{"leaf", ao::test::make_leaf()}}) {
    const Bounds3 b = object.bounds();
    const float e = b.diagonal();
    const Vec3 c = b.center();
    test::GpuFixture f{test::scene_of({object, make_quad({c.x - e, b.lo.y, c.z + e}, {c.x + e, b.lo.y, c.z + e}, {c.x + e, b.lo.y, c.z - e},
                                                         {c.x - e, b.lo.y, c.z - e})}),
                       nullptr, nullptr, {}, 0.1f * e};
    f.rays = std::make_unique<RayScene>(f.scene);
    f.gpu_scene = std::make_unique<GpuScene>(GpuScene::upload(gpu_device(), f.scene));
    f.g = render_gbuffer(*f.rays, frame_bounds(b, {1.0f, 0.8f, 1.3f}, 40.0f, 96, 72));
    const nlohmann::json params = find_method("cone").default_params();
    const MethodInput in{f.g, f.rays.get(), {Membership::Step, f.radius}, 7, {}, &f.scene.analytic};
    const MethodOutput cpu = run_method(in, find_method("cone").decode(params));
    const GpuMethodOutput gpu = run_gpu_method(gpu_device(), in, find_method("cone").decode(params));
    expect_agreement(gpu.output.visibility, cpu.visibility, what);
    EXPECT_GE(cpu.stats["side_grids"], 2) << what;
    EXPECT_EQ(gpu.output.stats["side_grids"], cpu.stats["side_grids"]) << what;
    EXPECT_EQ(gpu.output.stats["back_pixels"], cpu.stats["back_pixels"]) << what;
    EXPECT_GT(cpu.stats["back_pixels"], 100) << what;
    EXPECT_EQ(gpu.output.stats["rim_pixels"], cpu.stats["rim_pixels"]) << what;
    if (std::string_view(what) == "leaf") {
      EXPECT_GT(cpu.stats["rim_pixels"], 100) << what;
    }
  }
}

std::string agreement_name(const ::testing::TestParamInfo<std::tuple<std::string, std::string>>& p) {
  std::string n = std::get<0>(p.param) + "_" + std::get<1>(p.param);
  std::replace(n.begin(), n.end(), '-', '_');
  return n;
}

INSTANTIATE_TEST_SUITE_P(Methods, GpuMethodAgreement,
                         ::testing::Combine(::testing::Values("containment", "volumetric", "transfer", "alchemy", "gtao", "cone"),
                                            ::testing::Values("default", "sphere-on-plane", "box-room", "closed")),
                         agreement_name);

// The parameters that change a kernel's path: ray steps (containment's m = 1 loop), the
// normaliser, no interleaving or no filter, other memberships, one layer's sheets (thickness), the
// multi-bounce fit, Alchemy's contrast (pow) and preset, cone's presets and fixed pattern.
struct Variant {
  std::string method;
  nlohmann::json params;
  Membership membership = Membership::Linear;
};

class GpuMethodVariants : public ::testing::TestWithParam<Variant> {};

TEST_P(GpuMethodVariants, AgreeWithTheCpuKernel) {
  const Variant& v = GetParam();
  static const test::GpuFixture f = gpu_fixture("default", 80, 48);
  nlohmann::json params = gpu_params(v.method);
  params.update(v.params);
  const MethodInput in{f.g, f.rays.get(), {v.membership, 0.5f * f.radius}, 11, {}, &f.scene.analytic};
  const MethodOutput cpu = run_method(in, find_method(v.method).decode(params));
  const GpuMethodOutput gpu = run_gpu_method(gpu_device(), in, find_method(v.method).decode(params));
  expect_agreement(gpu.output.visibility, cpu.visibility, v.method + " " + v.params.dump());
  ASSERT_EQ(gpu.output.color.size(), cpu.color.size());
  for (int c = 0; c < 3 && !cpu.color.empty(); ++c) {
    Image<float> a(cpu.color.width(), cpu.color.height()), b(a.width(), a.height());
    for (std::size_t i = 0; i < a.size(); ++i) a[i] = gpu.output.color[i][c], b[i] = cpu.color[i][c];
    expect_agreement(a, b, v.method + " colour channel " + std::to_string(c));
  }
}

INSTANTIATE_TEST_SUITE_P(
    Parameters, GpuMethodVariants,
    ::testing::Values(Variant{"containment", {{"ray_steps", 1}, {"samples", 16}}}, Variant{"containment", {{"interleave", false}}, Membership::Step},
                      Variant{"containment", {{"silhouette_elimination", false}, {"bias", 0.01}}, Membership::Exp},
                      Variant{"volumetric", {{"normalizer", "analytic"}, {"filter", false}}}, Variant{"volumetric", {{"samples", 32}}},
                      Variant{"transfer", {{"ray_steps", 1}, {"albedo_scale", 0.5}}}, Variant{"transfer", {{"ray_steps", 3}}, Membership::Cubic},
                      Variant{"containment", {{"thickness", 0.3}}, Membership::Step}, Variant{"volumetric", {{"thickness", 0.3}}},
                      Variant{"transfer", {{"thickness", 0.3}, {"ray_steps", 3}}},
                      Variant{"alchemy", {{"contrast", 2.0}, {"filter", false}}}, Variant{"alchemy", {{"preset", "paper"}, {"samples", 24}}},
                      Variant{"gtao", {{"multi_bounce", true}}}, Variant{"gtao", {{"slices", 4}, {"steps", 12}, {"step_power", 2.0}}},
                      Variant{"cone", {{"preset", "high"}}}, Variant{"cone", {{"jitter", false}, {"filter_taps", 1}, {"depth_bits", 256}}}),
    [](const ::testing::TestParamInfo<Variant>& p) { return p.param.method + "_" + std::to_string(p.index); });

TEST(GpuMethods, TransferRadianceModeReadsTheDirectLightPass) {
  test::GpuFixture f = gpu_fixture("sphere-on-plane", 80, 48);
  f.g.direct = render_direct_light(*f.rays, f.g, Sun{normalize(Vec3{-1, 2, 1}), kPi});
  nlohmann::json params = gpu_params("transfer");
  params["reflectance"] = "radiance";
  const MethodInput in{f.g, f.rays.get(), {Membership::Step, 0.5f * f.radius}, 3, {}, &f.scene.analytic};
  const MethodOutput cpu = run_method(in, find_method("transfer").decode(params));
  const GpuMethodOutput gpu = run_gpu_method(gpu_device(), in, find_method("transfer").decode(params));
  expect_agreement(gpu.output.visibility, cpu.visibility, "transfer radiance");
  // Sunlit occluders send more light than the sky they hide somewhere: the mode did something.
  EXPECT_GT(*std::max_element(gpu.output.visibility.pixels().begin(), gpu.output.visibility.pixels().end()), 1.0f);
}

TEST(GpuMethods, OpenPlaneIsFullyVisible) {
  const test::GpuFixture f = gpu_fixture("plane", 64, 40);
  for (const MethodInfo& info : all_methods()) {
    // Not cone: the GPU voxelizes by parity, which fills everything above an open plane (each
    // column crosses it once; the paper's voxelization needs closed meshes).
    if (!info.gpu || info.name == "cone") continue;
    const std::string m(info.name);
    const GpuMethodOutput out = run_gpu_method(gpu_device(), MethodInput{f.g, f.rays.get(), {Membership::Step, 2.0f}, 1}, find_method(m).decode(gpu_params(m)));
    // As AllMethods.OpenPlaneIsFullyVisible: volumetric's pipes run along the camera's z and read
    // z* along the view ray through their middle, an error of order R / depth (below 0.01 here).
    for (std::size_t i = 0; i < out.output.visibility.size(); ++i) {
      ASSERT_GE(out.output.visibility[i], 0.99f) << m << " pixel " << i;
      ASSERT_LE(out.output.visibility[i], 1.0f + 1e-6f) << m << " pixel " << i;  // transfer's luminance of W rounds
    }
  }
}

TEST(GpuMethods, SameSeedSameImageAndAnotherSeedAnother) {
  const test::GpuFixture f = gpu_fixture("default", 64, 40);
  for (const char* m : {"containment", "alchemy", "cone"}) {
    const auto run = [&](std::uint32_t seed) {
      return run_gpu_method(gpu_device(), MethodInput{f.g, f.rays.get(), {Membership::Linear, 0.5f * f.radius}, seed}, find_method(m).decode(gpu_params(m))).output.visibility;
    };
    const Image<float> a = run(5), b = run(5), c = run(6);
    EXPECT_TRUE(std::equal(a.pixels().begin(), a.pixels().end(), b.pixels().begin())) << m;
    EXPECT_FALSE(std::equal(a.pixels().begin(), a.pixels().end(), c.pixels().begin())) << m;
  }
}

// Each method's error against its matched reference (the registry's, ray-traced on the same
// G-buffer) within 0.002 of the CPU's, on the CPU's G-buffer (both backends on the same input) and
// on the GPU's own rasterized one (the whole GPU path; its reference ray-traced on that G-buffer).
class GpuMethodRmse : public ::testing::TestWithParam<std::string> {};

TEST_P(GpuMethodRmse, WithinTwoThousandthsOfTheCpuBackend) {
  const std::string& method = GetParam();
  // Cone on closed meshes: the GPU voxelizes by parity, which fills the space above the default
  // scene's open ground and inside box-room's closed room (RMSE 0.93 and 0.95 on both backends
  // alike, which would say nothing).
  static const test::GpuFixture scenes[2] = {gpu_fixture("default", 96, 64), gpu_fixture("closed", 96, 64)};
  const test::GpuFixture& f = scenes[method == "cone" ? 1 : 0];
  const MethodInfo& m = find_method(method);
  const nlohmann::json params = gpu_params(method);
  const Falloff requested{Membership::Linear, 0.5f * f.radius};
  RaytracedParams rp;
  rp.samples = 64;  // the same reference image for both backends: its noise cancels in the difference
  const auto rmse = [&](const GBuffer& g, const Image<float>& v) {
    const ReferenceImage ref = render_reference(*f.rays, g, matched_reference(requested, m.decode(params)), rp, 1);
    return compare_images(v, ref.scalar.visibility, coverage_mask(g)).rmse;
  };
  const double cpu = rmse(f.g, run_method({f.g, f.rays.get(), requested, 9, {}, &f.scene.analytic}, m.decode(params)).visibility);
  const double gpu = rmse(f.g, run_gpu_method(gpu_device(), MethodInput{f.g, f.rays.get(), requested, 9}, find_method(method).decode(params)).output.visibility);
  EXPECT_NEAR(gpu, cpu, 0.002) << method;
  const GpuGBuffer raster = GpuGBuffer::rasterize(gpu_device(), *f.gpu_scene, f.g.camera);
  const GpuMethodOutput whole = run_gpu_method(gpu_device(), GpuMethodInput{raster, f.gpu_scene.get(), requested, 9}, find_method(method).decode(params));
  const double rasterized = rmse(raster.download(), whole.output.visibility);
  EXPECT_NEAR(rasterized, cpu, 0.002) << method << " on the rasterized G-buffer";
  std::printf("%s: RMSE against its reference %.5f (CPU), %.5f (GPU, same G-buffer), %.5f (GPU, rasterized G-buffer)\n", method.c_str(), cpu, gpu,
              rasterized);
}

INSTANTIATE_TEST_SUITE_P(Methods, GpuMethodRmse, ::testing::Values("containment", "volumetric", "transfer", "alchemy", "gtao", "cone"));

TEST(GpuMethods, WhatTheGpuDoesNotImplementIsAOneLineInputError) {
  const test::GpuFixture f = gpu_fixture("sphere-on-plane", 32, 20);
  const MethodInput in{f.g, f.rays.get(), {Membership::Step, 1.0f}, 1, {}, &f.scene.analytic};
  const auto fails = [&](const std::string& method, const nlohmann::json& params, const std::string& problem) {
    test::expect_one_line_error<InputError>([&] { run_gpu_method(gpu_device(), in, find_method(method).decode(params)); }, method, problem);
  };
  fails("containment", {{"characteristic", "implicit"}}, "depth buffer only");
  fails("volumetric", {{"characteristic", "nonsense"}}, "characteristic must be one of");
  fails("cone", {{"grid", "eye"}}, "world grid only");
  fails("raytraced", nlohmann::json::object(), "CPU only");
  fails("nonsense", nlohmann::json::object(), "unknown method");
  fails("gtao", {{"slices", 99}}, "slices");
  fails("alchemy", {{"no_such_key", 1}}, "unknown parameter");
}

TEST(GpuMethods, ConeWithoutASceneIsRefused) {
  const test::GpuFixture f = gpu_fixture("box-room", 32, 20);
  const GpuGBuffer g = GpuGBuffer::upload(gpu_device(), f.g);
  test::expect_one_line_error<InputError>([&] { run_gpu_method(gpu_device(), GpuMethodInput{g, nullptr, {Membership::Step, 1.0f}, 1}, find_method("cone").decode(nlohmann::json::object())); },
                                          "cone", "voxelizes the scene");
}

TEST(GpuMethods, ConeReusesItsGridWhileTheVoxelizationOptionsStay) {
  const test::GpuFixture f = gpu_fixture("box-room", 48, 32);
  const GpuGBuffer g = GpuGBuffer::upload(gpu_device(), f.g);
  const auto run = [&](const nlohmann::json& params) {
    return run_gpu_method(gpu_device(), GpuMethodInput{g, f.gpu_scene.get(), {Membership::Step, 1.0f}, 1}, find_method("cone").decode(params));
  };
  // box-room's camera is inside its room: the GPU voxelizes it by parity (the paper's), the default refuses.
  EXPECT_FALSE(run({{"columns", 64}, {"open_meshes", "parity"}}).output.stats["grid_reused"].get<bool>());
  const GpuMethodOutput again = run({{"columns", 64}, {"preset", "low"}, {"open_meshes", "parity"}});
  EXPECT_TRUE(again.output.stats["grid_reused"].get<bool>());
  EXPECT_FALSE(again.output.stats["gpu_ms"].contains("voxelize"));
  EXPECT_FALSE(run({{"columns", 96}, {"open_meshes", "parity"}}).output.stats["grid_reused"].get<bool>());
  // By default the room's solid is outside it, the CPU's voxelization: its grid, uploaded.
  const GpuMethodOutput room = run({{"columns", 64}});
  EXPECT_FALSE(room.output.stats["grid_reused"].get<bool>());
  EXPECT_TRUE(room.output.stats["gpu_ms"].contains("voxelize on the CPU"));
  EXPECT_FALSE(room.output.stats["gpu_ms"].contains("voxelize"));
}

}  // namespace
}  // namespace ao
