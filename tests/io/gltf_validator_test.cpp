// SPDX-License-Identifier: Apache-2.0
// Every kind of GLB the tests write, checked by the Khronos glTF-Validator (npm gltf-validator,
// installed by scripts/setup when the npm registry is reachable). Without node or the validator the
// test is SKIPPED with the reason, never passed silently.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/gltf_docs.h"
#include "support/run.h"

namespace ao::test {
namespace {

namespace fs = std::filesystem;

struct Validation {
  bool ran = false;
  std::string why_not;                // when !ran
  std::vector<nlohmann::json> files;  // one report per file
};

// Runs tests/support/validate_gltf.js on `files` with node, finding a global npm install.
Validation validate(const std::vector<fs::path>& files) {
  Validation v;
  std::string cmd = "command -v node >/dev/null 2>&1 || { echo '{\"error\":\"node is not installed\"}'; exit 3; }; NODE_PATH=\"$(npm root -g 2>/dev/null)\" node '" +
                    std::string(AO_TESTS_DIR) + "/support/validate_gltf.js'";
  for (const fs::path& f : files) cmd += " '" + f.string() + "'";
  FILE* pipe = popen(cmd.c_str(), "r");  // /bin/sh -c cmd
  std::string out;
  std::array<char, 4096> buf;
  while (pipe && fgets(buf.data(), static_cast<int>(buf.size()), pipe)) out += buf.data();
  const int status = pipe ? pclose(pipe) : -1;
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    const auto j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_discarded()) continue;
    if (j.contains("file")) v.files.push_back(j);
    else if (j.contains("error")) v.why_not = j["error"].get<std::string>();
  }
  v.ran = WIFEXITED(status) && WEXITSTATUS(status) != 3 && WEXITSTATUS(status) != 127;
  if (!v.ran && v.why_not.empty()) v.why_not = "could not run node";
  return v;
}

// A unit cube with its six faces in a 3 x 2 grid of the UV square.
std::string cube_obj() {
  std::ostringstream s;
  s << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";
  const int faces[6][4] = {{1, 4, 3, 2}, {5, 6, 7, 8}, {1, 2, 6, 5}, {4, 8, 7, 3}, {1, 5, 8, 4}, {2, 3, 7, 6}};
  for (int f = 0; f < 6; ++f) {
    const double u0 = (f % 3) / 3.0 + 0.02, u1 = (f % 3 + 1) / 3.0 - 0.02, v0 = (f / 3) / 2.0 + 0.02, v1 = (f / 3 + 1) / 2.0 - 0.02;
    s << "vt " << u0 << " " << v0 << "\nvt " << u1 << " " << v0 << "\nvt " << u1 << " " << v1 << "\nvt " << u0 << " " << v1 << "\n";
  }
  for (int f = 0; f < 6; ++f) {
    s << "f";
    for (int k = 0; k < 4; ++k) s << " " << faces[f][k] << "/" << 4 * f + k + 1;
    s << "\n";
  }
  return s.str();
}

TEST(GltfValidator, EveryKindOfGlbTheTestsWriteHasNoErrorsOrWarnings) {
  TempDir dir;
  write_text(dir / "cube.obj", cube_obj());
  const std::string rays = " --samples 4 --padding 2 -s 16 ";
  // The GLBs of the bake tests: map, 16-bit map, non-square map, per-vertex COLOR_0, a glTF input
  // baked again (materials carried over), and the glTF round trip of an instanced scene.
  ASSERT_EQ(run_ao("bake cube.obj --gltf map.glb" + rays, dir.path()).exit_code, 0);
  ASSERT_EQ(run_ao("bake cube.obj --gltf map16.glb --png-bits 16" + rays, dir.path()).exit_code, 0);
  ASSERT_EQ(run_ao("bake cube.obj --gltf wide.glb --samples 4 -s 32x8", dir.path()).exit_code, 0);
  ASSERT_EQ(run_ao("bake cube.obj --per-vertex vertex.glb --samples 4", dir.path()).exit_code, 0);
  ASSERT_EQ(run_ao("bake map.glb --gltf again.glb" + rays, dir.path()).exit_code, 0);
  write_text(dir / "pair.glb", instanced_cubes_glb());
  write_text(dir / "shared.glb", shared_material_glb());
  ASSERT_EQ(run_ao("bake pair.glb --gltf pair-map.glb --per-vertex pair-vertex.glb" + rays, dir.path()).exit_code, 0);
  ASSERT_EQ(run_ao("bake shared.glb --gltf shared-maps.glb --png-bits 16" + rays, dir.path()).exit_code, 0);
  const std::vector<fs::path> glbs = {dir / "map.glb",      dir / "map16.glb",        dir / "wide.glb",         dir / "vertex.glb",
                                      dir / "again.glb",    dir / "pair-map.glb",     dir / "pair-vertex.glb", dir / "shared-maps.glb"};
  const Validation v = validate(glbs);
  if (!v.ran) GTEST_SKIP() << "gltf-validator did not run: " << v.why_not << " (scripts/setup installs it when the npm registry is reachable)";
  ASSERT_EQ(v.files.size(), glbs.size());
  for (const nlohmann::json& r : v.files) {
    ASSERT_FALSE(r.contains("error")) << r.dump();
    EXPECT_EQ(r["errors"], 0) << r.dump();
    EXPECT_EQ(r["warnings"], 0) << r.dump();
  }
}

}  // namespace
}  // namespace ao::test
