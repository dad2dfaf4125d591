// SPDX-License-Identifier: Apache-2.0
// `ao compare` end to end: runs the built binary (AO_CLI_PATH) on tiny images and checks exit codes,
// outputs and their contents; bad input exits non-zero with one line and leaves no output directory.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "ao/io/image_io.h"
#include "ao/io/text.h"
#include "support/run.h"

namespace {

namespace fs = std::filesystem;

using ao::test::RunResult;

// `env` goes before the binary, e.g. "AO_FONT=/x".
RunResult run_ao(const std::string& args, const std::string& env = "") { return ao::test::run_ao_under(env, "-q " + args); }

nlohmann::json read_json(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

TEST(CompareCli, WritesTableSheetAndSweep) {
  const ao::test::TempDir dir;
  const fs::path out = dir / "out";
  const RunResult r = run_ao("compare sphere-on-plane --methods alchemy --width 48 --height 32 --spp-reference 8 --sweep samples=4,8 --out-dir " +
                       out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"table.md", "table.json", "sheet.png", "sweep.md", "sweep.json"}) EXPECT_TRUE(fs::exists(out / f)) << f;
  const nlohmann::json t = read_json(out / "table.json");
  ASSERT_EQ(t["rows"].size(), 1u);
  const nlohmann::json& row = t["rows"][0];
  EXPECT_EQ(row["method"], "alchemy");
  for (const char* k : {"ms", "rmse", "psnr_db", "ssim", "mean_signed_error", "parameters"}) EXPECT_TRUE(row.contains(k)) << k;
  // Alchemy is judged against step obscurance within its r at any intensity (the reference never
  // follows sigma, the estimator's own knob), and the table says so.
  EXPECT_EQ(row["reference"]["kind"], "obscurance");
  EXPECT_EQ(row["reference"]["membership"], "step");
  EXPECT_EQ(row["reference"]["label"], "step obscurance");
  EXPECT_GE(row["rmse"].get<double>(), 0.0);
  EXPECT_LE(row["rmse"].get<double>(), 1.0);
  const nlohmann::json s = read_json(out / "sweep.json");
  ASSERT_EQ(s["rows"].size(), 2u);
  EXPECT_EQ(s["rows"][1]["samples"], 8);
  // One 48x32 image per column, 4-pixel gutters, and with the font a header and a label above.
  const ao::Image<ao::Vec3> sheet = ao::read_rgb_image(out / "sheet.png");
  EXPECT_GE(sheet.width(), 3 * 48 + 4 * 4);
  if (fs::exists(ao::kDejaVuSansPath)) {
    EXPECT_GT(sheet.height(), 32 + 2 * 4 + 2 * 12) << "room for a header and a label of 12-pixel text";
  }
  // No staging directory is left beside the output.
  for (const auto& e : fs::directory_iterator(out.parent_path())) EXPECT_EQ(e.path().filename().string().find(".out.tmp"), std::string::npos);
}

bool same_pixels(const ao::Image<ao::Vec3>& a, int ax, int ay, const ao::Image<ao::Vec3>& b, int bx, int by, int w, int h) {
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (!(a(ax + x, ay + y) == b(bx + x, by + y))) return false;
  return true;
}

// The same comparison with and without the font: the labelled sheet is the unlabelled one's images,
// untouched, below a header and a label with text (bright pixels) and the heat map's colour scale
// (pure red and pure blue); without the font the sheet is still written, with a one-line warning.
TEST(CompareCli, SheetHasHeaderAndLabelsAboveUntouchedImagesAndWorksWithoutFont) {
  if (!fs::exists(ao::kDejaVuSansPath)) GTEST_SKIP() << ao::kDejaVuSansPath << " missing (scripts/setup installs fonts-dejavu-core)";
  constexpr int kW = 160, kH = 120, kGap = 4;
  const std::string args = "compare sphere-on-plane --methods alchemy --width 160 --height 120 --spp-reference 4 --out-dir ";
  const ao::test::TempDir dir;
  const fs::path labelled = dir / "labelled", plain = dir / "plain";
  RunResult r = run_ao(args + labelled.string(), "AO_FONT=");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  r = run_ao(args + plain.string(), "AO_FONT=/nonexistent/font.ttf");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto warning = r.err.find("warning: /nonexistent/font.ttf: no such font file");
  ASSERT_NE(warning, std::string::npos) << r.err;
  EXPECT_NE(r.err.find("no labels", warning), std::string::npos) << r.err;
  EXPECT_LT(r.err.find("no labels", warning), r.err.find('\n', warning)) << "one line: " << r.err;

  const ao::Image<ao::Vec3> with = ao::read_rgb_image(labelled / "sheet.png"), without = ao::read_rgb_image(plain / "sheet.png");
  ASSERT_EQ(without.width(), 3 * kW + 4 * kGap);
  ASSERT_EQ(without.height(), kH + 2 * kGap);
  ASSERT_GE(with.width(), without.width());
  ASSERT_GT(with.height(), without.height() + 12) << "a header and a label";
  const int col_w = (with.width() - 4 * kGap) / 3, top = with.height() - kGap - kH;
  for (int c = 0; c < 3; ++c)
    EXPECT_TRUE(same_pixels(with, kGap + c * (col_w + kGap), top, without, kGap + c * (kW + kGap), kGap, kW, kH)) << "column " << c;
  int text = 0, red = 0, blue = 0;
  for (int y = 0; y < top; ++y)
    for (int x = 0; x < with.width(); ++x) {
      const ao::Vec3 p = with(x, y);
      text += p.x > 0.6f && p.y > 0.6f && p.z > 0.6f;
      red += p.x > 0.9f && p.y < 0.1f && p.z < 0.1f;
      blue += p.z > 0.9f && p.x < 0.1f && p.y < 0.1f;
    }
  EXPECT_GT(text, 100);
  EXPECT_GT(red, 0);
  EXPECT_GT(blue, 0);
}

// The characteristic function is a parameter like any other: set per method, and swept.
TEST(CompareCli, SweepsTheCharacteristicFunction) {
  const ao::test::TempDir dir;
  const fs::path out = dir / "characteristic";
  const RunResult r = run_ao("compare sphere-on-plane --methods containment,volumetric --width 48 --height 32 --spp-reference 8 -R 0.5 "
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
  const ao::test::TempDir dir;
  const fs::path out = dir / "bad-method";
  const RunResult r = run_ao("compare plane --methods alchemy,nonsense --width 16 --height 16 --out-dir " + out.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("unknown method 'nonsense'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("alchemy"), std::string::npos) << "the error lists the known methods: " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(CompareCli, MissingMeshFailsWithOneLineAndNoOutput) {
  const ao::test::TempDir dir;
  const fs::path out = dir / "missing-mesh";
  const RunResult r = run_ao("compare /nonexistent/cow.off --methods alchemy --width 16 --height 16 --out-dir " + out.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("cow.off"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(CompareCli, BadSweepAndParamFailBeforeRendering) {
  const ao::test::TempDir dir;
  const fs::path out = dir / "bad-sweep";
  RunResult r = run_ao("compare plane --methods alchemy --sweep nosuchkey=1,2 --out-dir " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_FALSE(fs::exists(out));
  r = run_ao("compare plane --methods alchemy -p alchemy.sigma=2 --out-dir " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("intensity"), std::string::npos) << "lists the method's parameters: " << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// Each method gets its matched reference by default; --reference NAME overrides for every method,
// METHOD=NAME for one.
TEST(CompareCli, ChoosesReferencesByName) {
  const ao::test::TempDir dir;
  const fs::path out = dir / "references";
  const std::string base = "compare sphere-on-plane --methods volumetric,transfer --width 32 --height 24 --spp-reference 4 --out-dir ";
  RunResult r = run_ao(base + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json t = read_json(out / "table.json");
  EXPECT_EQ(t["rows"][0]["reference"]["kind"], "tangent-sphere");
  EXPECT_EQ(t["rows"][1]["reference"]["kind"], "transfer");
  r = run_ao(base + out.string() + " --reference obscurance");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  t = read_json(out / "table.json");
  EXPECT_EQ(t["rows"][0]["reference"]["label"], "cubic obscurance");
  EXPECT_EQ(t["rows"][1]["reference"]["label"], "step obscurance");
  r = run_ao(base + out.string() + " --reference volumetric=obscurance");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  t = read_json(out / "table.json");
  EXPECT_EQ(t["rows"][0]["reference"]["label"], "cubic obscurance");
  EXPECT_EQ(t["rows"][1]["reference"]["kind"], "transfer");
  const fs::path bad = dir / "bad-reference";
  r = run_ao(base + bad.string() + " --reference cubic");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("unknown reference 'cubic'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(bad));
  r = run_ao(base + bad.string() + " --reference cone=obscurance");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_FALSE(fs::exists(bad));
}

// Parameters print at the precision they were given: Alchemy's float bias of 1e-4 is "0.0001" in
// both tables, not the double expansion of the float, 9.999999747378752e-05.
TEST(CompareCli, TablesPrintFloatsAsGiven) {
  const ao::test::TempDir dir;
  const fs::path out = dir / "floats";
  const RunResult r = run_ao("compare sphere-on-plane --methods alchemy --width 16 --height 12 --spp-reference 2 --out-dir " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream md(out / "table.md"), js(out / "table.json");
  std::stringstream a, b;
  a << md.rdbuf();
  b << js.rdbuf();
  EXPECT_NE(a.str().find("bias=0.0001"), std::string::npos) << a.str();
  EXPECT_EQ(a.str().find("e-05"), std::string::npos) << a.str();
  EXPECT_EQ(b.str().find("9.99999"), std::string::npos) << b.str();
}

}  // namespace
