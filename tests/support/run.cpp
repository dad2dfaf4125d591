// SPDX-License-Identifier: Apache-2.0
#include "support/run.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <fstream>
#include <iterator>
#include <sstream>

namespace ao::test {

void expect_one_line_error(const RunResult& r, const std::string& needle, int exit_code) {
  EXPECT_EQ(r.exit_code, exit_code) << r.err;
  EXPECT_EQ(r.err.rfind("ao: error: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos) << "expected '" << needle << "' in: " << r.err;
}

namespace {
std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}
}  // namespace

namespace {
RunResult run_command(const std::string& command, const std::string& args, const std::filesystem::path& cwd) {
  TempDir capture;
  const std::string cd = cwd.empty() ? "" : "cd " + quote(cwd.string()) + " && ";
  // Progress lines in a log come once a day here, so that what a test reads on stderr does not
  // depend on how long the run took (under a sanitizer, on a loaded machine); a test of progress
  // sets its own interval (`env AO_PROGRESS_SECONDS=...` in run_ao_under's prefix wins).
  const std::string cmd = cd + "AO_PROGRESS_SECONDS=86400 " + command + " " + args + " </dev/null >" + quote((capture / "out").string()) + " 2>" +
                          quote((capture / "err").string());
  const int status = std::system(cmd.c_str());
  RunResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_text(capture / "out");
  r.err = read_text(capture / "err");
  return r;
}
}  // namespace

RunResult run_ao(const std::string& args, const std::filesystem::path& cwd) { return run_command(quote(AO_CLI_PATH), args, cwd); }

RunResult run_ao_under(const std::string& prefix, const std::string& args, const std::filesystem::path& cwd) {
  // LeakSanitizer cannot run under ptrace: in a sanitizer build, a run under strace would end in
  // its fatal error (exit 1) instead of ao's exit code. AddressSanitizer's other checks still run.
  const std::string no_leak_check = prefix.starts_with("strace ") ? "ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0 " : "";
  return run_command(no_leak_check + prefix + " " + quote(AO_CLI_PATH), args, cwd);
}

RunResult run_ao_limited(const std::string& ulimits, const std::string& args, const std::filesystem::path& cwd) {
  const std::string script = "ulimit " + ulimits + " && trap '' XFSZ && exec \"$0\" \"$@\"";
  return run_command("bash -c " + quote(script) + " " + quote(AO_CLI_PATH), args, cwd);
}

TempDir::TempDir() {
  static std::atomic<int> counter{0};
  path_ = std::filesystem::temp_directory_path() /
          ("ao-test-" + std::to_string(getpid()) + "-" + std::to_string(counter++));
  std::filesystem::remove_all(path_);
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::filesystem::path TempDir::write(const std::string& name, const std::string& content) const {
  write_text(path_ / name, content);
  return path_ / name;
}

int TempDir::file_count() const {
  return static_cast<int>(std::distance(std::filesystem::directory_iterator(path_), std::filesystem::directory_iterator()));
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

// xvfb-run searching for a free display from a number of this test's own: parallel tests starting
// Xvfb with -a from the same number can pick the same display, and a stale lock (a killed Xvfb)
// must not fail the test.
std::string xvfb() {
  static std::atomic<int> counter{0};
  const int server = 200 + static_cast<int>(getpid() % 500) * 8 + (counter++ % 8);
  // In the sanitizer build, leak checking is off for the window's process: Mesa's OpenGL driver,
  // loaded and unloaded at run time, leaves a few small allocations at exit that LeakSanitizer
  // reports from an unnamed module (nothing of ours).
  return "xvfb-run -a -n " + std::to_string(server) + " -s '-screen 0 640x480x24' env ASAN_OPTIONS=detect_leaks=0";
}

}  // namespace ao::test
