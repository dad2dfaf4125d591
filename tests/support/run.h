// SPDX-License-Identifier: Apache-2.0
// Runs the `ao` binary the way a user or a script does and captures what it says.
#pragma once

#include <filesystem>
#include <string>

namespace ao::test {

struct RunResult {
  int exit_code = -1;
  std::string out;  ///< stdout
  std::string err;  ///< stderr
};

/// Runs `AO_CLI_PATH args` through the shell in `cwd` (the current directory when empty).
RunResult run_ao(const std::string& args, const std::filesystem::path& cwd = {});
/// The same with `prefix` before the binary (e.g. "xvfb-run -a" for a command that opens a window).
/// Under strace (a prefix starting "strace "), LeakSanitizer is off: it cannot run under ptrace.
RunResult run_ao_under(const std::string& prefix, const std::string& args, const std::filesystem::path& cwd = {});

/// The prefix that runs a command in a virtual X display of its own (xvfb-run, 640 x 480), for
/// run_ao_under: `ao view` needs a display.
std::string xvfb();

/// run_ao under resource limits: `ulimits` are bash `ulimit` options ("-f 64": files of at most
/// 64 KiB; "-v 4194304": 4 GiB of address space). SIGXFSZ is ignored, so a write beyond -f fails
/// with EFBIG, as on a full disk, instead of killing the process.
RunResult run_ao_limited(const std::string& ulimits, const std::string& args, const std::filesystem::path& cwd = {});

/// `r` failed with exit code `exit_code` (1: bad input; 3: system failure) and one line on stderr,
/// "ao: error: ..." containing `needle`.
void expect_one_line_error(const RunResult& r, const std::string& needle, int exit_code = 1);

/// A fresh empty directory under the system temp directory, removed by the destructor: one per
/// test, so tests never see each other's files.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }
  /// Writes `content` to the file `name` in the directory and returns its path.
  std::filesystem::path write(const std::string& name, const std::string& content) const;
  /// Entries directly in the directory (to check that nothing, not even a temporary file, was left).
  int file_count() const;

 private:
  std::filesystem::path path_;
};

/// Writes `text` to `path`.
void write_text(const std::filesystem::path& path, const std::string& text);
std::string read_text(const std::filesystem::path& path);

}  // namespace ao::test
