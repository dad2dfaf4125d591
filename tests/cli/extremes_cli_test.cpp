// SPDX-License-Identifier: Apache-2.0
// Every numeric option at the extremes a script or a typo produces (0, -1, 1e9, 2e18, inf, nan):
// either a result or one line naming the option, exit 1, and nothing written; never a crash, a
// hang or a half-written file. Values in range are accepted (a 1e9 distance is a long reach).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "support/run.h"

namespace ao {
namespace {

constexpr const char* kTriangleObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n";

struct Probe {
  std::string command;  // ends where the option goes
  std::string option;
  std::string output;   // the file a success writes
};

TEST(Extremes, EveryNumericOptionGetsAResultOrOneLineNamingIt) {
  const std::string render = "render -o v.png --width 8 --height 8 -q", bake = "bake t.obj -o m.png -s 16 -q";
  const std::vector<Probe> probes = {
      {"render -o v.png --height 8 -q", "--width", "v.png"}, {"render -o v.png --width 8 -q", "--height", "v.png"},        {render, "--fov", "v.png"},
      {render, "--radius", "v.png"},                {render, "--radius-fraction", "v.png"}, {render, "--tau", "v.png"},
      {render, "--samples", "v.png"},         {render, "--target-error", "v.png"},  {render, "--seed", "v.png"},
      {render, "--png-bits", "v.png"},        {"bake t.obj -o m.png -q", "--size", "m.png"},                {bake, "--samples", "m.png"},
      {bake, "--denoise", "m.png"},           {bake, "--max-distance", "m.png"},    {bake, "--offset", "m.png"},
      {bake, "--padding", "m.png"},           {bake, "--cage-points", "m.png"},     {bake, "--uv-set", "m.png"},
      {bake, "--seed", "m.png"},              {"bake t.obj -o m.png -s 16 -m histogram -q", "-d", "m.png"},
      {"compare --methods gtao --out-dir c --width 8 --height 8 -q", "--reference-samples", "c/table.json"},
  };
  for (const Probe& p : probes)
    for (const std::string value : {"0", "-1", "1e9", "2e18", "inf", "nan"}) {
      test::TempDir dir;
      std::ofstream(dir / "t.obj") << kTriangleObj;
      // Values that are in range but would make a long run (1e9 samples) are refused or fast here:
      // every option's upper bound is checked before any work.
      const std::string args = p.command + " " + p.option + " " + value;
      const test::RunResult r = test::run_ao(args, dir.path());
      ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 1) << args << ": exit " << r.exit_code << "\n" << r.err;
      if (r.exit_code == 0) {
        EXPECT_TRUE(std::filesystem::exists(dir / p.output)) << args;
        continue;
      }
      // Named as typed (--target-error) or as its parameter (target_error).
      std::string name = p.option.substr(2), param = name;
      std::replace(param.begin(), param.end(), '-', '_');
      test::expect_one_line_error(r, "");
      EXPECT_TRUE(r.err.find(name) != std::string::npos || r.err.find(param) != std::string::npos) << args << ": " << r.err;
      EXPECT_FALSE(std::filesystem::exists(dir / p.output)) << args << ": an output after an error";
    }
}

}  // namespace
}  // namespace ao
