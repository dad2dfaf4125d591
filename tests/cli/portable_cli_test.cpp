// SPDX-License-Identifier: Apache-2.0
// The default (portable) build of `ao` on a baseline x86-64 CPU: under qemu-x86_64 -cpu Nehalem
// (SSE4.2, no AVX; Debian's qemu-user) it runs, its kernels pick a target without AVX, and its
// images match this machine's run of the same binary within the targets' agreement
// (tests/methods/simd_targets_test.cpp), Embree's own dispatch (its SSE4.2 kernels there, its
// AVX2/AVX-512 ones here) and glibc's (its sin and cos differ in the last bit between their FMA and
// SSE2 variants). Small images: the emulation is slow. Skipped without qemu, in an AO_NATIVE build
// (tied to this CPU by design) and under the sanitizers (their shadow memory does not map under qemu).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

#include "ao/io/image_io.h"
#include "support/run.h"

namespace ao {
namespace {

using test::run_ao;
using test::run_ao_under;
using test::TempDir;

const char* const kNehalem = "qemu-x86_64 -cpu Nehalem";

bool have_qemu() { return std::system("command -v qemu-x86_64 >/dev/null 2>&1") == 0; }

struct Agreement {
  double mean = 0;  // mean |a - b| over the pixels
  float max = 0;
};

Agreement compare(const Image<float>& a, const Image<float>& b) {
  Agreement g;
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const float e = std::abs(a[i] - b[i]);
    sum += e;
    g.max = std::max(g.max, e);
  }
  g.mean = sum / static_cast<double>(a.size());
  return g;
}

// A floor and a wall meeting at a right angle, with UVs (floor left half, wall right half): a bake
// with occlusion along the crease.
const char* const kCreaseObj =
    "v 0 0 0\nv 2 0 0\nv 2 0 2\nv 0 0 2\nv 0 2 0\nv 2 2 0\n"
    "vt 0.02 0.02\nvt 0.48 0.02\nvt 0.48 0.98\nvt 0.02 0.98\nvt 0.52 0.02\nvt 0.98 0.02\nvt 0.98 0.98\nvt 0.52 0.98\n"
    "f 4/4 3/3 2/2 1/1\nf 1/5 2/6 6/7 5/8\n";

class PortableBuild : public ::testing::Test {
 protected:
  void SetUp() override {
#if AO_NATIVE_BUILD
    GTEST_SKIP() << "an AO_NATIVE build runs on its own CPU only";
#endif
#ifdef AO_SANITIZED
    GTEST_SKIP() << "sanitizer builds do not run under qemu";
#endif
    if (!have_qemu()) GTEST_SKIP() << "qemu-x86_64 not installed (scripts/setup installs qemu-user)";
  }

  // Runs `args` (writing `output` in dir) natively and under the emulated Nehalem, and compares.
  Agreement both(const std::string& args, const std::string& output) {
    const test::RunResult here = run_ao("--threads 2 -q " + args + " -o here-" + output, dir.path());
    EXPECT_EQ(here.exit_code, 0) << here.err;
    const test::RunResult there = run_ao_under(kNehalem, "--threads 2 -q " + args + " -o nehalem-" + output, dir.path());
    EXPECT_EQ(there.exit_code, 0) << there.err;
    if (here.exit_code != 0 || there.exit_code != 0) return {1, 1};
    return compare(read_image(dir / ("here-" + output)), read_image(dir / ("nehalem-" + output)));
  }

  TempDir dir;
};

TEST_F(PortableBuild, VersionNamesATargetWithoutAvx) {
  const test::RunResult r = run_ao_under(kNehalem, "--version");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("SIMD: "), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("AVX"), std::string::npos) << "a Nehalem has no AVX: " << r.out;
}

// The kernels' targets agree within 1e-3 on average and 0.25 at worst (simd_targets_test.cpp).
TEST_F(PortableBuild, VolumetricAndConeMatchThisMachine) {
  const std::string view = "render default --width 64 --height 40 ";
  const Agreement v = both(view + "-m volumetric", "volumetric.exr");
  EXPECT_LE(v.mean, 1e-3) << "volumetric";
  EXPECT_LE(v.max, 0.25f) << "volumetric";
  const Agreement c = both(view + "-m cone", "cone.exr");
  EXPECT_LE(c.mean, 1e-3) << "cone";
  EXPECT_LE(c.max, 0.25f) << "cone";
}

// The reference: the same seeds and rays, but Embree's SSE4.2 traversal and glibc's SSE2 sin and
// cos. A ray that grazes a surface or ends within rounding of R can change its verdict: one ray of
// a pixel's 32 (1/32) at worst in a pixel, and rarely (mean 1e-3: one flipped ray in 3% of the pixels).
TEST_F(PortableBuild, RaytracedReferenceMatchesThisMachine) {
  const Agreement r = both("render default --width 64 --height 40 -m raytraced --spp 32", "raytraced.exr");
  EXPECT_LE(r.mean, 1e-3);
  EXPECT_LE(r.max, 1.0f / 32 + 1e-6f);
}

// A ray-traced bake (the default method) of a crease: the same tolerance as the reference, per
// texel of 16 rays (1/16), and as much again through the denoiser, which averages neighbours.
TEST_F(PortableBuild, BakeMatchesThisMachine) {
  test::write_text(dir / "crease.obj", kCreaseObj);
  const Agreement b = both("bake crease.obj --size 32 --samples 16", "map.exr");
  EXPECT_LE(b.mean, 2e-3);
  EXPECT_LE(b.max, 2.0f / 16 + 1e-6f);
}

}  // namespace
}  // namespace ao
