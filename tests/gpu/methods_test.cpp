// The methods on the GPU against the CPU kernels on the same G-buffer (uploaded), with the same
// parameters, seed, sample sets and rotations.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <tuple>

#include "ao/gpu/methods.h"
#include "gpu/gpu_support.h"

namespace ao {
namespace {

using test::gpu_device;
using test::gpu_fixture;

struct Difference {
  double max_abs = 0, mean_abs = 0;
  std::size_t over_1e5 = 0, over_1e3 = 0, pixels = 0;
};

Difference difference(const Image<float>& a, const Image<float>& b) {
  Difference d;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double e = std::abs(static_cast<double>(a[i]) - b[i]);
    d.max_abs = std::max(d.max_abs, e);
    d.mean_abs += e;
    d.over_1e5 += e > 1e-5 ? 1 : 0;
    d.over_1e3 += e > 1e-3 ? 1 : 0;
  }
  d.pixels = a.size();
  d.mean_abs /= static_cast<double>(a.size());
  return d;
}

class GpuMethodAgreement : public ::testing::TestWithParam<std::tuple<std::string, std::string>> {};

TEST_P(GpuMethodAgreement, AgreesWithTheCpuKernelOnTheSameGBuffer) {
  const auto& [method, scene] = GetParam();
  const test::GpuFixture f = gpu_fixture(scene, 96, 64);
  const MethodInfo& m = find_method(method);
  nlohmann::json params = m.default_params();
  if (method == "cone") params["open_meshes"] = "parity";
  const Falloff falloff{Membership::Linear, 0.5f * f.radius};
  const MethodInput in{f.g, f.rays.get(), falloff, 7, {}, &f.scene.analytic};
  const MethodOutput cpu = m.run(in, params);
  const GpuMethodOutput gpu = run_gpu_method(gpu_device(), method, in, params);
  const Difference d = difference(gpu.output.visibility, cpu.visibility);
  std::printf("%s %s: max %.3g mean %.3g, >1e-5: %zu, >1e-3: %zu of %zu\n", method.c_str(), scene.c_str(), d.max_abs, d.mean_abs, d.over_1e5,
              d.over_1e3, d.pixels);
  for (const GpuPassTime& p : gpu.passes) std::printf("  %s %.3f ms\n", p.name.c_str(), p.ms);
}

INSTANTIATE_TEST_SUITE_P(Methods, GpuMethodAgreement,
                         ::testing::Combine(::testing::Values("containment", "volumetric", "transfer", "alchemy", "gtao", "cone"),
                                            ::testing::Values("default", "sphere-on-plane", "box-room")),
                         [](const ::testing::TestParamInfo<std::tuple<std::string, std::string>>& p) {
                           std::string n = std::get<0>(p.param) + "_" + std::get<1>(p.param);
                           std::replace(n.begin(), n.end(), '-', '_');
                           return n;
                         });

}  // namespace
}  // namespace ao
