// SPDX-License-Identifier: Apache-2.0
// `ao tune` end to end: it writes a parameter file that `ao render -p @FILE` loads; bad input exits 1.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/run.h"

namespace ao {
namespace {

TEST(TuneCli, WritesAParameterFileThatRenderLoads) {
  const test::TempDir dir;
  const auto file = dir / "alchemy.json";
  test::RunResult r = test::run_ao("-q tune --scenes sphere-on-plane,wedge -m alchemy --fit intensity=0.1:2 --budget 30 --width 48 "
                                   "--height 32 --spp-reference 8 -o " + file.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(test::read_text(file));
  EXPECT_EQ(j.at("method"), "alchemy");
  EXPECT_LE(j.at("best_rmse").get<double>(), j.at("start_rmse").get<double>());
  const double intensity = j.at("parameters").at("intensity").get<double>();
  r = test::run_ao("-q render sphere-on-plane -m alchemy --width 16 --height 12 --json -p @" + file.string() + " -o " + (dir / "a.png").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.find("\"intensity\": " + j.at("parameters").at("intensity").dump()) != std::string::npos, true) << r.out << intensity;
}

TEST(TuneCli, BadInputFailsWithOneLine) {
  const test::TempDir dir;
  test::RunResult r = test::run_ao("-q tune -m alchemy --fit sigma=0:1 -o " + (dir / "x.json").string());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("sigma"), std::string::npos) << r.err;
  r = test::run_ao("-q tune -m alchemy --fit intensity=a:b -o " + (dir / "x.json").string());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(dir.file_count(), 0);
  const auto bad = dir.write("bad.json", "[1, 2]");
  r = test::run_ao("-q render plane -m alchemy --width 8 --height 8 -p @" + bad.string() + " -o " + (dir / "a.png").string());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("bad.json"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace ao
