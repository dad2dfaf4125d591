// `ao compare` end to end: runs the built binary (AO_CLI_PATH) on tiny images and checks exit codes,
// outputs and their contents; bad input exits non-zero with one line and leaves no output directory.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;

struct CliRun {
  int exit_code;
  std::string err;
};

fs::path scratch(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("ao-compare-test-" + std::to_string(::getpid())) / name;
  fs::remove_all(p);
  fs::create_directories(p.parent_path());
  return p;
}

CliRun run_ao(const std::string& args) {
  const fs::path err = scratch("stderr.txt");
  const std::string cmd = std::string(AO_CLI_PATH) + " -q " + args + " > /dev/null 2> " + err.string();
  const int status = std::system(cmd.c_str());
  std::ifstream in(err);
  std::stringstream s;
  s << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, s.str()};
}

nlohmann::json read_json(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

TEST(CompareCli, WritesTableSheetAndSweep) {
  const fs::path out = scratch("out");
  const CliRun r = run_ao("compare sphere-on-plane --methods alchemy --width 48 --height 32 --spp-reference 8 --sweep samples=4,8 --out-dir " +
                       out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"table.md", "table.json", "sheet.png", "sweep.md", "sweep.json"}) EXPECT_TRUE(fs::exists(out / f)) << f;
  const nlohmann::json t = read_json(out / "table.json");
  ASSERT_EQ(t["rows"].size(), 1u);
  const nlohmann::json& row = t["rows"][0];
  EXPECT_EQ(row["method"], "alchemy");
  for (const char* k : {"ms", "rmse", "psnr_db", "ssim", "mean_signed_error", "parameters"}) EXPECT_TRUE(row.contains(k)) << k;
  EXPECT_EQ(row["reference"]["membership"], "alchemy");
  EXPECT_GE(row["rmse"].get<double>(), 0.0);
  EXPECT_LE(row["rmse"].get<double>(), 1.0);
  const nlohmann::json s = read_json(out / "sweep.json");
  ASSERT_EQ(s["rows"].size(), 2u);
  EXPECT_EQ(s["rows"][1]["samples"], 8);
  // No staging directory is left beside the output.
  for (const auto& e : fs::directory_iterator(out.parent_path())) EXPECT_EQ(e.path().filename().string().find(".out.tmp"), std::string::npos);
}

// The characteristic function is a parameter like any other: set per method, and swept.
TEST(CompareCli, SweepsTheCharacteristicFunction) {
  const fs::path out = scratch("characteristic");
  const CliRun r = run_ao("compare sphere-on-plane --methods containment,volumetric --width 48 --height 32 --spp-reference 8 -R 0.5 "
                          "-p volumetric.characteristic=implicit --sweep characteristic=depth,implicit --out-dir " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json t = read_json(out / "table.json");
  ASSERT_EQ(t["rows"].size(), 2u);
  EXPECT_EQ(t["rows"][0]["parameters"]["characteristic"], "depth");
  EXPECT_EQ(t["rows"][1]["parameters"]["characteristic"], "implicit");
  const nlohmann::json s = read_json(out / "sweep.json");
  ASSERT_EQ(s["rows"].size(), 4u);
  EXPECT_EQ(s["rows"][1]["characteristic"], "implicit");
}

TEST(CompareCli, UnknownMethodFailsWithOneLineAndNoOutput) {
  const fs::path out = scratch("bad-method");
  const CliRun r = run_ao("compare plane --methods alchemy,nonsense --width 16 --height 16 --out-dir " + out.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("unknown method 'nonsense'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("alchemy"), std::string::npos) << "the error lists the known methods: " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(CompareCli, MissingMeshFailsWithOneLineAndNoOutput) {
  const fs::path out = scratch("missing-mesh");
  const CliRun r = run_ao("compare /nonexistent/cow.off --methods alchemy --width 16 --height 16 --out-dir " + out.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("cow.off"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(CompareCli, BadSweepAndParamFailBeforeRendering) {
  const fs::path out = scratch("bad-sweep");
  CliRun r = run_ao("compare plane --methods alchemy --sweep nosuchkey=1,2 --out-dir " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_FALSE(fs::exists(out));
  r = run_ao("compare plane --methods alchemy -p alchemy.sigma=2 --out-dir " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("intensity"), std::string::npos) << "lists the method's parameters: " << r.err;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
