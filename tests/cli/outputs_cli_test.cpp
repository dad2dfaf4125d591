// SPDX-License-Identifier: Apache-2.0
// The outputs of `ao render`, `ao bake` and `ao compare` as one transaction (SPEC, "Behaviour on
// bad input"; output_set.h): a write that fails late leaves the earlier outputs as they were, an
// output that names an input or another output is refused before any work, and a run killed by
// SIGTERM or SIGINT leaves no temporary file. Also the one-line messages of bad option values and
// the memory estimate that refuses a run too big for the machine before it starts.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <sstream>
#include <thread>

#include "ao/core/memory.h"
#include "support/run.h"

extern char** environ;

namespace ao::test {
namespace {

namespace fs = std::filesystem;


// Names in `dir` (recursively) that start with '.': the temporary files of the writers.
// Safe while a running process creates and removes files there.
int hidden_files(const fs::path& dir) {
  int n = 0;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) n += it->path().filename().string().rfind('.', 0) == 0;
  return n;
}

// `ao args` in `dir` with files limited to `kib` KiB: a write beyond fails (EFBIG) at the point it
// happens, as on a full disk.
RunResult run_ao_with_file_limit(const std::string& args, const fs::path& dir, int kib) {
  return run_ao_limited("-f " + std::to_string(kib), args, dir);
}

// A w x w grid in the unit square as OBJ with UVs: (w+1)^2 vertices, for outputs of a known size.
std::string grid_obj(int w) {
  std::ostringstream s;
  for (int y = 0; y <= w; ++y)
    for (int x = 0; x <= w; ++x) s << "v " << x / double(w) << " " << y / double(w) << " " << ((x * 7 + y * 3) % 5) * 0.01 << "\n";
  for (int y = 0; y <= w; ++y)
    for (int x = 0; x <= w; ++x) s << "vt " << 0.02 + 0.96 * x / w << " " << 0.02 + 0.96 * y / w << "\n";
  for (int y = 0; y < w; ++y)
    for (int x = 0; x < w; ++x) {
      const int a = y * (w + 1) + x + 1, b = a + 1, c = a + w + 2, d = a + w + 1;
      s << "f " << a << "/" << a << " " << b << "/" << b << " " << c << "/" << c << "\n";
      s << "f " << a << "/" << a << " " << c << "/" << c << " " << d << "/" << d << "\n";
    }
  return s.str();
}

TEST(OutputsCli, RenderLateWriteFailureKeepsTheEarlierOutputAndLeavesNoTemporaryFile) {
  TempDir dir;
  write_text(dir / "v.png", "previous contents");
  // v.png (200 x 150, 8 bit: at most 31 KB) fits under 64 KiB; the G-buffer EXR (15 float
  // channels, 1.8 MB raw) does not, so the second write fails after the first was written.
  const RunResult r = run_ao_with_file_limit("render plane --width 200 --height 150 --spp 4 -o v.png --gbuffer-out g.exr", dir.path(), 64);
  expect_one_line_error(r, "g.exr", 3);
  EXPECT_EQ(read_text(dir / "v.png"), "previous contents");
  EXPECT_FALSE(fs::exists(dir / "g.exr"));
  EXPECT_EQ(dir.file_count(), 1);
  // Without the limit both are written (the limit, not the options, made it fail).
  ASSERT_EQ(run_ao("render plane --width 200 --height 150 --spp 4 -o v.png --gbuffer-out g.exr", dir.path()).exit_code, 0);
  EXPECT_GT(fs::file_size(dir / "g.exr"), 64u * 1024u);
  EXPECT_LT(fs::file_size(dir / "v.png"), 64u * 1024u);
}

TEST(OutputsCli, BakeLateWriteFailureKeepsTheEarlierOutputsAndLeavesNoTemporaryFile) {
  TempDir dir;
  write_text(dir / "grid.obj", grid_obj(100));
  write_text(dir / "ao.png", "previous map");
  // A 16 x 16 map is under 1 KiB; the per-vertex PLY of 10,201 vertices and 20,000 triangles is
  // about 450 KB, over the 64 KiB limit: it is written last and fails.
  const std::string args = "bake grid.obj -m histogram -o ao.png --per-vertex v.ply --size 16 --directions 16 --vertex-resolution 64";
  const RunResult r = run_ao_with_file_limit(args, dir.path(), 64);
  expect_one_line_error(r, "v.ply", 3);
  EXPECT_EQ(read_text(dir / "ao.png"), "previous map");
  EXPECT_FALSE(fs::exists(dir / "v.ply"));
  EXPECT_EQ(dir.file_count(), 2);
  ASSERT_EQ(run_ao(args, dir.path()).exit_code, 0);
  EXPECT_GT(fs::file_size(dir / "v.ply"), 64u * 1024u);
}

TEST(OutputsCli, OutputThatIsAnInputOrAnotherOutputIsRefusedBeforeAnyWork) {
  TempDir dir;
  ASSERT_EQ(run_ao("render plane --width 40 --height 30 --spp 4 -o v.png --gbuffer-out g.exr", dir.path()).exit_code, 0);
  write_text(dir / "grid.obj", grid_obj(4));
  ASSERT_EQ(run_ao("bake grid.obj -m histogram --size 16 --directions 16 -o ao.png --per-vertex in.ply --gltf in.glb", dir.path()).exit_code, 0);
  fs::create_symlink("g.exr", dir / "link.exr");
  const std::string g = read_text(dir / "g.exr"), ply = read_text(dir / "in.ply"), glb = read_text(dir / "in.glb");
  const std::pair<const char*, const char*> cases[] = {
      {"render --gbuffer-in g.exr -m alchemy -o g.exr", "is the input of --gbuffer-in"},
      {"render --gbuffer-in g.exr -m alchemy -o w.png --gbuffer-out g.exr", "is the input of --gbuffer-in"},
      {"bake in.ply --per-vertex in.ply", "is the input of the mesh"},
      {"bake in.ply --per-vertex ./in.ply", "is the input of the mesh"},
      {"bake in.glb --gltf in.glb --size 16", "is the input of the mesh"},
      {"render plane -o X.png --shaded X.png", "both -o and --shaded"},
      {"render --gbuffer-in g.exr -m alchemy -o link.exr", "is the input of --gbuffer-in"},
      {"bake grid.obj --size 16 -o m.png --bent-normals m.png", "both -o and --bent-normals"},
  };
  for (const auto& [args, needle] : cases) {
    const RunResult r = run_ao(args, dir.path());
    EXPECT_EQ(r.exit_code, 1) << args << ": " << r.err;
    expect_one_line_error(r, needle);
  }
  EXPECT_EQ(read_text(dir / "g.exr"), g);
  EXPECT_EQ(read_text(dir / "in.ply"), ply);
  EXPECT_EQ(read_text(dir / "in.glb"), glb);
  for (const char* f : {"X.png", "w.png", "m.png"}) EXPECT_FALSE(fs::exists(dir / f)) << f;
  EXPECT_EQ(hidden_files(dir.path()), 0);
}

TEST(OutputsCli, CompareWritesNothingWhenItFailsLate) {
  TempDir dir;
  // The sheet is written after the tables; a limit of 4 KiB lets the tables (about 1 KB each)
  // through and stops it (over 7 KB).
  const std::string args = "compare plane --methods alchemy --width 128 --height 96 --spp-reference 4 --out-dir out";
  const RunResult r = run_ao_with_file_limit(args, dir.path(), 4);
  expect_one_line_error(r, "sheet.png", 3);
  EXPECT_FALSE(fs::exists(dir / "out"));
  EXPECT_EQ(dir.file_count(), 0);
  ASSERT_EQ(run_ao(args, dir.path()).exit_code, 0);
  EXPECT_LT(fs::file_size(dir / "out" / "table.json"), 4096u);
  EXPECT_GT(fs::file_size(dir / "out" / "sheet.png"), 4096u);
}

// Starts `ao -q args` in `dir` (stderr to /dev/null) and returns its pid, or -1.
pid_t spawn_ao(const std::string& args, const fs::path& dir) {
  std::vector<std::string> words = {AO_CLI_PATH, "-q"};
  std::istringstream in(args);
  for (std::string w; in >> w;) words.push_back(w);
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  const fs::path cwd = fs::current_path();
  fs::current_path(dir);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, words[0].c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  fs::current_path(cwd);
  return rc == 0 ? pid : -1;
}

// Starts `ao args` in `dir`, waits until one of its hidden temporary files exists (it is then
// writing its outputs), sends `sig`, and returns the wait status; -1 if the run ended first.
int kill_while_writing(const std::string& args, const fs::path& dir, int sig) {
  const pid_t pid = spawn_ao(args, dir);
  if (pid < 0) return -2;
  int status = 0;
  for (;;) {
    if (::waitpid(pid, &status, WNOHANG) == pid) return -1;  // finished before we saw a temporary file
    if (hidden_files(dir) > 0) break;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  ::kill(pid, sig);
  ::waitpid(pid, &status, 0);
  return status;
}

TEST(OutputsCli, SignalDuringTheWritesLeavesNoTemporaryFile) {
  for (const int sig : {SIGTERM, SIGINT}) {
    TempDir dir;
    write_text(dir / "v.png", "previous contents");
    // A big G-buffer EXR takes a while to write, a window the polling above catches; the sizes
    // grow until it does (a fast machine may write the smaller one before the first poll).
    int status = -1;
    for (int width = 1000; width <= 4000 && status == -1; width *= 2) {
      status = kill_while_writing("render plane -m alchemy --width " + std::to_string(width) + " --height " + std::to_string(width) +
                                      " -o v.png --shaded s.png --gbuffer-out g.exr",
                                  dir.path(), sig);
      if (status == -1) {  // finished: start again from the original state
        for (const auto& e : fs::directory_iterator(dir.path())) fs::remove(e.path());
        write_text(dir / "v.png", "previous contents");
      }
    }
    ASSERT_NE(status, -1) << "the run always finished before a temporary file was seen";
    ASSERT_NE(status, -2) << "cannot start " << AO_CLI_PATH;
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << status;
    EXPECT_EQ(hidden_files(dir.path()), 0) << "signal " << sig;
    EXPECT_EQ(read_text(dir / "v.png"), "previous contents");
    EXPECT_EQ(dir.file_count(), 1);
  }
}

TEST(OutputsCli, BadOptionValuesNameTheOptionAndItsRange) {
  TempDir dir;
  const std::pair<const char*, const char*> cases[] = {
      {"render plane -o v.png --width 0", "--width must be in [1, 32768] pixels, got 0"},
      {"render plane -o v.png --height 40000", "--height must be in [1, 32768] pixels, got 40000"},
      {"render plane -o v.png --fov 0", "--fov must be in (0, 180) degrees, got 0"},
      {"render plane -o v.png -p samples=1e12", "got 1e12"},
      {"render plane -o v.png -p samples=2.5", "whole number"},
      {"render plane -o v.png --width abc", "--width"},
      {"render plane -o v.png --seed -1", "--seed"},
      {"bake --size x m.obj -o v.png", "--size"},
      {"compare plane --width 0 --out-dir out", "--width must be in [1, 32768]"},
      {"render plane -o v.png --radius-fraction 0", "--radius-fraction must be in (0, 10]"},
      {"render plane -o v.png --membership nope", "nope"},
  };
  for (const auto& [args, needle] : cases) {
    const RunResult r = run_ao(args, dir.path());
    EXPECT_EQ(r.exit_code, 1) << args << ": " << r.err;
    expect_one_line_error(r, needle);
  }
  EXPECT_EQ(dir.file_count(), 0);
}

TEST(OutputsCli, OptionsAreCheckedBeforeTheMeshIsRead) {
  TempDir dir;
  // A missing mesh would be the first error if it were read first.
  const RunResult r = run_ao("render missing.obj --fov 0 -o v.png", dir.path());
  EXPECT_EQ(r.exit_code, 1);
  expect_one_line_error(r, "--fov");
}

TEST(OutputsCli, RunsTooBigForTheMemoryAreRefusedUpFrontWithTheEstimate) {
#ifdef AO_SANITIZED
  GTEST_SKIP() << "address-space limits and peak memory mean nothing under AddressSanitizer's shadow memory";
#endif
  TempDir dir;
  // A 4 GiB address-space limit makes the available memory known and small on any machine.
  const auto limited = [&](const std::string& args) { return run_ao_limited("-v 4194304", args, dir.path()); };
  RunResult r = limited("render plane --width 32768 --height 32768 -o v.png");
  expect_one_line_error(r, "32768x32768 pixels needs about", 3);
  EXPECT_NE(r.err.find("RLIMIT_AS"), std::string::npos) << r.err;
  write_text(dir / "grid.obj", grid_obj(2));
  r = limited("bake grid.obj -s 16384 -o m.png");
  expect_one_line_error(r, "16384x16384 map needs about", 3);
  // Cone tracing's largest voxel grid (4096^2 columns x 1024 bits: 2.1 GB of bits) counts too.
  r = limited("render plane --width 64 --height 48 -m cone -p columns=4096 -p depth_bits=1024 -o v.png");
  expect_one_line_error(r, "4096^2 x 1024 voxel grid needs about", 3);
  // Small runs fit under the same limit.
  r = limited("render plane --width 64 --height 48 --spp 4 -o v.png");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(fs::exists(dir / "m.png"));
}

// The estimate is an upper bound of the real peak: the peak resident size of the run (wait4's
// rusage) of the method with the largest per-pixel scratch
// (transfer) stays below it, and is not far below it (within 3x, so the estimate refuses no run
// that needs a third of the memory).
TEST(OutputsCli, RenderMemoryEstimateBoundsTheMeasuredPeak) {
#ifdef AO_SANITIZED
  GTEST_SKIP() << "address-space limits and peak memory mean nothing under AddressSanitizer's shadow memory";
#endif
  TempDir dir;
  const int w = 1024;
  const pid_t pid = spawn_ao("render plane -m transfer --width 1024 --height 1024 -o v.png --shaded s.png", dir.path());
  ASSERT_GT(pid, 0);
  int status = 0;
  rusage usage{};
  ASSERT_EQ(::wait4(pid, &status, 0, &usage), pid);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  const double peak = static_cast<double>(usage.ru_maxrss) * 1024.0;  // KiB on Linux
  const double estimate = static_cast<double>(estimate_render_memory({.width = w, .height = w, .shaded = true}));
  EXPECT_LT(peak, estimate);
  EXPECT_GT(peak, estimate / 3.0);
}

}  // namespace
}  // namespace ao::test
