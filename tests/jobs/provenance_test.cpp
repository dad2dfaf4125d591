// SPDX-License-Identifier: Apache-2.0
// Outputs that know how they were made (jobs/provenance.h): `--provenance` writes beside each
// output its record, with the hashes of what was read and written and every setting; every JSON
// names the build; run_points estimates V at given points.
#include "ao/jobs/provenance.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/jobs/points.h"
#include "ao/simd/target.h"
#include "ao/version.h"
#include "support/run.h"

namespace ao {
namespace {

namespace fs = std::filesystem;

const char* kQuad = "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 4/4 3/3 2/2\n";

nlohmann::json read_json(const fs::path& p) { return nlohmann::json::parse(test::read_text(p)); }

TEST(Provenance, Sha256IsTheStandardOne) {
  test::TempDir dir;
  // FIPS 180-2, appendix B.1 ("abc") and the empty message.
  EXPECT_EQ(file_sha256(dir.write("abc", "abc")), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(file_sha256(dir.write("empty", "")), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_THROW(file_sha256(dir / "missing"), SystemError);
}

TEST(Provenance, BakeRecordsItsInputsSettingsAndOutput) {
  test::TempDir dir;
  const fs::path mesh = dir.write("quad.obj", kQuad);
  const test::RunResult r = test::run_ao("bake quad.obj -o map.png -s 16 --spp 4 --per-vertex v.ply --provenance", dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* out : {"map.png", "v.ply"}) {
    const nlohmann::json rec = read_json(dir / (std::string(out) + ".ao.json"));
    EXPECT_EQ(rec["ao"], (nlohmann::json{{"version", AO_VERSION_STRING}, {"simd_target", simd_target()}}));
    EXPECT_EQ(rec["job"], "bake");
    ASSERT_EQ(rec["inputs"].size(), 1u);
    EXPECT_EQ(rec["inputs"][0]["role"], "mesh");
    EXPECT_EQ(rec["inputs"][0]["sha256"], file_sha256(mesh));
    EXPECT_EQ(rec["inputs"][0]["bytes"], fs::file_size(mesh));
    EXPECT_EQ(rec["output"]["file"], out);
    EXPECT_EQ(rec["output"]["sha256"], file_sha256(dir / out));  // the record describes the file committed with it
    EXPECT_EQ(rec["outputs"], (nlohmann::json{"map.png", "v.ply"}));
    EXPECT_EQ(rec["settings"]["width"], 16);
    EXPECT_EQ(rec["settings"]["parameters"]["samples"], 4);
    EXPECT_EQ(rec["settings"]["outputs"]["per_vertex"], ".ply");
  }
  EXPECT_EQ(dir.file_count(), 5);  // the mesh, two outputs, two records: nothing else
}

TEST(Provenance, RenderRecordsEveryOutputAndNothingWithoutAsking) {
  test::TempDir dir;
  const test::RunResult r = test::run_ao("render wedge -m volumetric --width 16 --height 9 -o v.exr --shaded s.png --provenance --seed 7", dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json rec = read_json(dir / "s.png.ao.json");
  EXPECT_EQ(rec["job"], "render");
  EXPECT_EQ(rec["inputs"], nlohmann::json::array());  // a built-in scene: named in the settings
  EXPECT_EQ(rec["settings"]["scene"], "wedge");
  EXPECT_EQ(rec["settings"]["method"], "volumetric");
  EXPECT_EQ(rec["settings"]["seed"], 7);
  EXPECT_EQ(rec["settings"]["camera"]["width"], 16);
  EXPECT_EQ(rec["outputs"], (nlohmann::json{"v.exr", "s.png"}));
  EXPECT_TRUE(fs::exists(dir / "v.exr.ao.json"));
  EXPECT_EQ(dir.file_count(), 4);
  ASSERT_EQ(test::run_ao("render wedge -m volumetric --width 16 --height 9 -o w.exr", dir.path()).exit_code, 0);
  EXPECT_EQ(dir.file_count(), 5);  // without --provenance: the output alone
}

TEST(Provenance, AFailedRunLeavesNoRecord) {
  test::TempDir dir;
  dir.write("quad.obj", "v 0 0 0\nv 1 0 0\nv 0 0 1\nvt 0 0\nf 1/1 2/1 9/1\n");  // vertex 9 of 3
  const test::RunResult r = test::run_ao("bake quad.obj -o map.png -s 16 --provenance", dir.path());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(dir.file_count(), 1);
}

TEST(Provenance, EveryJsonNamesTheBuild) {
  test::TempDir dir;
  const test::RunResult r = test::run_ao("render wedge -m volumetric --width 16 --height 9 -o v.exr --json", dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["ao"], build_info());
  dir.write("quad.obj", kQuad);
  const test::RunResult b = test::run_ao("bake quad.obj -o map.png -s 16 --spp 4 --json", dir.path());
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_EQ(nlohmann::json::parse(b.out)["ao"], build_info());
  const test::RunResult c = test::run_ao("compare wedge --methods volumetric --width 16 --height 9 --spp-reference 4 --out-dir cmp", dir.path());
  ASSERT_EQ(c.exit_code, 0) << c.err;
  EXPECT_EQ(read_json(dir / "cmp" / "table.json")["ao"], build_info());
  EXPECT_EQ(build_info()["version"], AO_VERSION_STRING);
}

TEST(Points, OpenPlaneIsFullyVisibleAndBadPointsAreNamed) {
  PointsRequest r;
  r.scene.args = {"plane"};
  r.points = {{0, 0, 0}, {0.25f, 0, -0.25f}};
  r.normals = {{0, 1, 0}, {0, 3, 0}};  // normalised
  r.params.samples = 32;
  const PointsResult out = run_points(r);
  EXPECT_EQ(out.visibility, (std::vector<float>{1, 1}));
  EXPECT_EQ(out.std_error, (std::vector<float>{0, 0}));
  EXPECT_EQ(out.samples, (std::vector<int>{32, 32}));
  EXPECT_EQ(out.summary["rays"], 64);
  r.normals[1] = {0, 0, 0};
  try {
    run_points(r);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "PointsRequest::normals: normal 1 is not a finite non-zero vector");
  }
  r.normals.pop_back();
  EXPECT_THROW(run_points(r), InputError);
}

}  // namespace
}  // namespace ao
