// SPDX-License-Identifier: Apache-2.0
// Issue 41's reproducers, end to end: hostile files, parameters and environments that crashed `ao`,
// made it write where it should not, or gave a wrong result with exit 0. Each test runs the
// built binary (AO_CLI_PATH), so a crash shows as a failed expectation, not as a crash of the
// test program.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/gltf_docs.h"
#include "support/run.h"

namespace ao::test {
namespace {

namespace fs = std::filesystem;

// `depth` arrays nested in one another: "[[[...]]]".
std::string nested_arrays(int depth) { return std::string(static_cast<std::size_t>(depth), '[') + std::string(static_cast<std::size_t>(depth), ']'); }

// A unit square with UVs on a floor, as OBJ: something to bake.
constexpr const char* kQuadObj = "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 4/4 3/3 2/2\n";

// `args` run by a shell that first runs `setup` and then replaces itself by ao: $$ in `setup` is
// the pid ao will have.
RunResult run_ao_after(const std::string& setup, const std::string& args, const fs::path& dir) {
  std::string quoted;
  for (char c : setup) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return run_ao_under("bash -c '" + quoted + " && exec \"$0\" \"$@\"'", args, dir);
}

// --- no shared temporary (item 1) ---------------------------------------------------------------

// `bake --gltf` staged its embedded map at $TMPDIR/ao-bake-<pid>.png and wrote through a symbolic
// link planted there. Now nothing is written in $TMPDIR: the link's target keeps its content and
// the folder holds only what was planted.
TEST(UntrustedCli, BakeGltfWritesNothingInTheTemporaryFolder) {
  TempDir dir, tmp, elsewhere;
  dir.write("quad.obj", kQuadObj);
  const fs::path victim = elsewhere.write("victim.txt", "precious");
  const std::string plant = "ln -s " + victim.string() + " " + (tmp / "ao-bake-").string() + "$$.png";
  // A map that is not a PNG: the glTF's PNG was the staged scratch file.
  const RunResult r = run_ao_after("export TMPDIR=" + tmp.path().string() + " && " + plant, "bake quad.obj -o m.exr --gltf out.glb -s 32 --spp 4 -q", dir.path());
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(read_text(victim), "precious");
  EXPECT_EQ(tmp.file_count(), 1);
  // The GLB carries the map as its occlusion texture.
  const GlbFile glb = parse_glb_file(read_text(dir / "out.glb"));
  ASSERT_EQ(glb.json["images"].size(), 1u);
  EXPECT_EQ(glb_view(glb, glb.json["images"][0]["bufferView"].get<int>()).substr(0, 4), "\x89PNG");
}

// Temporary names were the pid and a counter from 0: files or links planted under them made the
// run fail ("cannot create a file"). Now names are random: the run writes, the links stay unused.
TEST(UntrustedCli, PlantedTemporaryNamesAreNeitherInTheWayNorFollowed) {
  TempDir dir, elsewhere;
  const fs::path victim = elsewhere.write("victim.png", "precious");
  const std::string plant = "for n in 0 1 2 3 4 5 6 7; do ln -s " + victim.string() + " .v.tmp-$$-$n.png; done";
  const RunResult r = run_ao_after(plant, "render plane -o v.png --width 16 --height 16 --spp 1 -q", dir.path());
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(read_text(victim), "precious");
  EXPECT_EQ(read_text(dir / "v.png").substr(0, 4), "\x89PNG");
}

// --- bake --gltf without its texture (item 7) ---------------------------------------------------

// When the map staged for the GLB could not be read back (EACCES, EIO, EMFILE), bake --gltf wrote
// the GLB without its occlusion texture and exited 0. With a failed open at each of the last
// steps of the run (strace's fault injection), the run now either fails cleanly, leaving nothing,
// or writes the map and a GLB that embeds it.
TEST(UntrustedCli, BakeGltfWithAFailedOpenAtEachStepFailsCleanlyOrEmbedsTheMap) {
  if (std::system("strace -o /dev/null true >/dev/null 2>&1") != 0) GTEST_SKIP() << "strace cannot trace here (not installed, or ptrace is not permitted)";
  TempDir dir;
  dir.write("quad.obj", kQuadObj);
  const std::string bake = "bake quad.obj -o m.png --gltf m.glb -s 16 --spp 2 -q";
  // How many files a successful run opens.
  ASSERT_EQ(run_ao_under("strace -f -qq -o opens.txt -e trace=openat", bake, dir.path()).exit_code, 0);
  const std::string trace = read_text(dir / "opens.txt");
  int opens = 0;
  for (std::size_t at = 0; (at = trace.find("openat(", at)) != std::string::npos; ++at) ++opens;
  ASSERT_GT(opens, 8);
  for (const char* f : {"opens.txt", "m.png", "m.glb"}) fs::remove(dir / f);
  // The writes come last: fail each of the last 12 opens in turn.
  for (int k = opens - 11; k <= opens; ++k) {
    SCOPED_TRACE("open " + std::to_string(k) + " of " + std::to_string(opens) + " fails");
    const RunResult r = run_ao_under("strace -f -qq -o /dev/null -e trace=openat -e inject=openat:error=EACCES:when=" + std::to_string(k), bake, dir.path());
    if (r.exit_code != 0) {
      EXPECT_TRUE(r.exit_code == 1 || r.exit_code == 3) << r.err;
      EXPECT_EQ(dir.file_count(), 1) << r.err;  // quad.obj only
      continue;
    }
    const GlbFile glb = parse_glb_file(read_text(dir / "m.glb"));
    ASSERT_TRUE(glb.json.contains("images")) << "exit 0, and the GLB has no occlusion texture";
    EXPECT_EQ(glb_view(glb, glb.json["images"][0]["bufferView"].get<int>()), read_text(dir / "m.png"));
    fs::remove(dir / "m.png");
    fs::remove(dir / "m.glb");
    EXPECT_EQ(dir.file_count(), 1);
  }
}

// --- JSON limits (item 2) -----------------------------------------------------------------------

// A camera file whose eye is 100,000 nested arrays (200 KB) crashed render on a stack overflow;
// 50,000 gave a 100 KB error line. Now one short line naming the file, for camera and parameter
// files alike, at any depth past the limit.
TEST(UntrustedCli, DeeplyNestedJsonIsOneShortLine) {
  TempDir dir;
  for (int depth : {65, 50000, 100000}) {
    SCOPED_TRACE(depth);
    dir.write("c.json", R"({"eye": )" + nested_arrays(depth) + R"(, "target": [0, 0, 0], "up": [0, 1, 0], "fov": 40})");
    dir.write("p.json", R"({"intensity": )" + nested_arrays(depth) + "}");
    std::vector<std::string> commands = {"render plane --camera c.json -o v.png", "render plane -m alchemy -p @p.json -o v.png"};
    // On the command line too, within the 128 KiB a single argument (the shell's command) may have.
    if (depth <= 50000) commands.push_back("render plane -m alchemy -p intensity=" + nested_arrays(depth) + " -o v.png");
    for (const std::string& args : commands) {
      const RunResult r = run_ao(args, dir.path());
      expect_one_line_error(r, "nests deeper than 64 levels");
      EXPECT_LT(r.err.size(), 200u);
    }
  }
  EXPECT_FALSE(fs::exists(dir / "v.png"));
}

// A value that is long but shallow is quoted in a message only in part.
TEST(UntrustedCli, LongJsonValuesAreNotEchoed) {
  TempDir dir;
  std::string many = "[1";
  for (int k = 0; k < 50000; ++k) many += ",1";
  many += "]";
  dir.write("c.json", R"({"eye": )" + many + R"(, "target": [0, 0, 0], "up": [0, 1, 0], "fov": 40})");
  dir.write("p.json", R"({"intensity": )" + many + "}");
  RunResult r = run_ao("render plane --camera c.json -o v.png", dir.path());
  expect_one_line_error(r, "c.json: camera 'eye' must be an array of three numbers");
  EXPECT_LT(r.err.size(), 200u);
  r = run_ao("render plane -m alchemy -p @p.json -o v.png", dir.path());
  expect_one_line_error(r, "intensity must be");
  EXPECT_LT(r.err.size(), 300u);
}

// --- file size limit (item 5) -------------------------------------------------------------------

// Under `ulimit -f` every writer died of SIGXFSZ (exit 153, no message, a temporary file left).
// Now "cannot write: the file size limit ...", exit 3, nothing left, in every image format.
TEST(UntrustedCli, FileSizeLimitIsAnErrorThatLeavesNothing) {
  TempDir dir;
  for (const std::string out : {"v.png", "v.exr", "v.tif", "v.jpg"}) {
    SCOPED_TRACE(out);
    const RunResult r = run_ao_after("ulimit -f 16", "render displaced -o " + out + " --width 512 --height 512 --spp 1 -q", dir.path());
    expect_one_line_error(r, out + ": cannot write: the file size limit (ulimit -f) of 16384 bytes is reached", 3);
    EXPECT_EQ(dir.file_count(), 0);
  }
}

// --- ao tune -o (item 6) ------------------------------------------------------------------------

// `ao tune -o` replaced its own inputs with JSON (exit 0). Now it is checked as render's outputs
// are: a .json name that is none of the files the run reads, refused before any work.
TEST(UntrustedCli, TuneOutputIsCheckedAgainstItsInputsAndExtension) {
  TempDir dir;
  const std::string mesh = "OFF\n4 2 0\n-1 0 -1\n1 0 -1\n1 0 1\n-1 0 1\n3 0 3 2\n3 0 2 1\n";
  dir.write("m.off", mesh);
  dir.write("c.json", R"({"eye": [0, 2, 2], "target": [0, 0, 0], "up": [0, 1, 0], "fov": 40})");
  dir.write("p.json", R"({"intensity": 0.7})");
  const std::string tune = "tune -m alchemy --fit intensity=0.5:1 --budget 1 ";
  expect_one_line_error(run_ao(tune + "--scenes m.off -o m.off", dir.path()), "m.off: -o is the parameter file, written as JSON; give it a .json name");
  expect_one_line_error(run_ao(tune + "--scenes m.off -o m.json.txt", dir.path()), ".json name");
  expect_one_line_error(run_ao(tune + "--scenes plane --camera c.json -o c.json", dir.path()), "c.json: the output of -o is the input of --camera");
  expect_one_line_error(run_ao(tune + "--scenes plane -p @p.json -o p.json", dir.path()), "p.json: the output of -o is the input of -p @p.json");
  fs::create_directory(dir / "d.json");
  expect_one_line_error(run_ao(tune + "--scenes plane -o d.json", dir.path()), "d.json: -o names a directory");
  EXPECT_EQ(read_text(dir / "m.off"), mesh);
  EXPECT_EQ(read_text(dir / "c.json"), R"({"eye": [0, 2, 2], "target": [0, 0, 0], "up": [0, 1, 0], "fov": 40})");
  EXPECT_EQ(read_text(dir / "p.json"), R"({"intensity": 0.7})");
  EXPECT_EQ(dir.file_count(), 4);
}

// --- memory estimates (item 11) -----------------------------------------------------------------

// compare had no memory estimate: 8000 x 8000 ran 95 s to 7.6 GB, then "out of memory". A
// per-vertex bake of many glTF instances passed the loader's estimate and then ran out of memory
// in assimp, which copies every instance into world space at several times the bytes counted.
// Both are refused before any work now, with the estimate, under a 4 GiB address-space limit.
TEST(UntrustedCli, CompareAndInstancedPerVertexBakesAreEstimatedBeforeWork) {
#ifdef AO_SANITIZED
  GTEST_SKIP() << "address-space limits mean nothing under AddressSanitizer's shadow memory";
#endif
  TempDir dir;
  const auto limited = [&](const std::string& args) { return run_ao_limited("-v 4194304", args, dir.path()); };
  expect_one_line_error(limited("compare plane --methods gtao --width 8000 --height 8000 -q"), "ao compare: 1 method at 8000x8000 pixels needs about", 3);
  // A 61 x 61 grid (7,442 triangles) used by 3,000 nodes: 22 million triangles in world space.
  const int n = 61;
  std::string bytes;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x)
      for (float c : {static_cast<float>(x) / n, 0.0f, static_cast<float>(y) / n}) bytes.append(reinterpret_cast<const char*>(&c), 4);
  const std::size_t index_offset = bytes.size();
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const std::uint32_t a = static_cast<std::uint32_t>(y * (n + 1) + x), b = a + 1, c = a + n + 2, d = a + n + 1;
      for (std::uint32_t i : {a, d, c, a, c, b}) bytes.append(reinterpret_cast<const char*>(&i), 4);
    }
  nlohmann::json doc = nlohmann::json::parse(R"({"asset": {"version": "2.0"}, "scene": 0,
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0}, {"buffer": 0}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "type": "VEC3", "min": [0, 0, 0], "max": [1, 0, 1]},
                  {"bufferView": 1, "componentType": 5125, "type": "SCALAR"}]})");
  doc["bufferViews"][0]["byteLength"] = index_offset;
  doc["bufferViews"][1]["byteOffset"] = index_offset;
  doc["bufferViews"][1]["byteLength"] = bytes.size() - index_offset;
  doc["accessors"][0]["count"] = (n + 1) * (n + 1);
  doc["accessors"][1]["count"] = 6 * n * n;
  nlohmann::json nodes = nlohmann::json::array(), roots = nlohmann::json::array();
  for (int k = 0; k < 3000; ++k) {
    nodes.push_back({{"mesh", 0}, {"translation", {1.5 * (k % 60), 0.1 * (k / 60), 0}}});
    roots.push_back(k);
  }
  doc["nodes"] = nodes;
  doc["scenes"] = {{{"nodes", roots}}};
  write_text(dir / "many.glb", make_glb(doc, bytes));
  expect_one_line_error(limited("bake many.glb --per-vertex pv.ply -q"), "many.glb: loading 22326000 triangles (3000 mesh uses, each a copy) needs about", 3);
  EXPECT_FALSE(fs::exists(dir / "pv.ply"));
}

// --- a multi-output commit that survives SIGKILL (item 16) --------------------------------------

// A run killed between two renames of its outputs left new and old outputs mixed, and the old
// files survived only as hidden links that a later run deleted. Now a journal lists the outputs
// before the first rename, and the next run that writes into the folder (here another file)
// rolls the commit back: every output as it was before the killed run, nothing hidden left.
TEST(UntrustedCli, ARunKilledBetweenTwoRenamesIsRolledBackByTheNextRun) {
  if (std::system("strace -o /dev/null true >/dev/null 2>&1") != 0) GTEST_SKIP() << "strace cannot trace here (not installed, or ptrace is not permitted)";
  TempDir dir;
  const std::vector<std::string> outputs = {"v.png", "s.png", "g.exr"};
  const std::string render = "render plane -o v.png --shaded s.png --gbuffer-out g.exr --width 16 --height 16 --spp 1 -q";
  for (int k : {2, 3}) {
    SCOPED_TRACE("killed at rename " + std::to_string(k));
    for (const std::string& o : outputs) write_text(dir / o, "old " + o);
    const RunResult killed = run_ao_under("strace -f -qq -o /dev/null -e trace=rename -e inject=rename:error=EIO:signal=SIGKILL:when=" + std::to_string(k), render, dir.path());
    EXPECT_NE(killed.exit_code, 0) << killed.err;
    ASSERT_EQ(run_ao("render plane -o other.png --width 8 --height 8 --spp 1 -q", dir.path()).exit_code, 0);
    for (const std::string& o : outputs) EXPECT_EQ(read_text(dir / o), "old " + o) << o;
    int hidden = 0;
    for (const auto& e : fs::directory_iterator(dir.path())) hidden += e.path().filename().string().starts_with(".");
    EXPECT_EQ(hidden, 0);
    fs::remove(dir / "other.png");
  }
  // Unhindered, the same run replaces all three and leaves no journal.
  ASSERT_EQ(run_ao(render, dir.path()).exit_code, 0);
  for (const std::string& o : outputs) EXPECT_NE(read_text(dir / o), "old " + o) << o;
  EXPECT_EQ(dir.file_count(), 3);
}

// --- minor (item 17) ----------------------------------------------------------------------------

// An output named with a line break was written, and its summary line broke in two. Such a name
// is refused before any work, the message on one line.
TEST(UntrustedCli, OutputNamesWithALineBreakAreRefused) {
  TempDir dir;
  const RunResult r = run_ao("render plane -o \"$(printf 'a\\nb.png')\" --width 8 --height 8", dir.path());
  expect_one_line_error(r, "'a?b.png': -o has a line break or another control character in its name");
  EXPECT_EQ(dir.file_count(), 0);
}

}  // namespace
}  // namespace ao::test
