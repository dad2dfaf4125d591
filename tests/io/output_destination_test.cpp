// Issue 27, outputs: only regular files or new paths are written (a FIFO, a device node or a
// symbolic link to one is refused before any work); a rename failing during OutputSet::commit
// leaves every previous output in place; temporary files of killed runs are removed; a full disk
// says so.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <chrono>
#include <string>

#include "ao/core/error.h"
#include "ao/io/atomic_file.h"
#include "ao/io/output_set.h"
#include "support/errors.h"
#include "support/run.h"

namespace ao::test {
namespace {

namespace fs = std::filesystem;

void write_atomically(const fs::path& path, const std::string& text) {
  write_file_atomically(path, [&](const fs::path& temp) { write_text(temp, text); });
}

int hidden_files(const fs::path& dir) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir)) n += e.path().filename().string().rfind('.', 0) == 0;
  return n;
}

/// The pid of a process that has ended (a child that exited and was reaped).
pid_t dead_pid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

TEST(OutputDestination, FifoIsRefusedByOutputSetAndByTheAtomicWriter) {
  TempDir dir;
  ASSERT_EQ(::mkfifo((dir / "pipe.png").c_str(), 0644), 0);
  OutputSet outputs;
  expect_one_line_error<InputError>([&] { outputs.add_output(dir / "pipe.png", "-o"); }, dir / "pipe.png", "-o is a FIFO (named pipe), not a regular file");
  expect_one_line_error<InputError>([&] { write_atomically(dir / "pipe.png", "x"); }, dir / "pipe.png", "is a FIFO (named pipe)");
  EXPECT_TRUE(fs::is_fifo(dir / "pipe.png"));
  EXPECT_EQ(hidden_files(dir.path()), 0);
}

TEST(OutputDestination, DeviceNodeAndSymbolicLinksToOneAreRefused) {
  TempDir dir;
  fs::create_symlink("/dev/null", dir / "null.png");
  OutputSet outputs;
  expect_one_line_error<InputError>([&] { outputs.add_output("/dev/null", "-o"); }, "/dev/null", "-o is a character device, not a regular file");
  expect_one_line_error<InputError>([&] { outputs.add_output(dir / "null.png", "--shaded"); }, dir / "null.png",
                                    "--shaded is a symbolic link to a character device");
  expect_one_line_error<InputError>([&] { write_atomically(dir / "null.png", "x"); }, dir / "null.png", "a symbolic link to a character device");
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  EXPECT_TRUE(fs::is_symlink(dir / "null.png"));
}

TEST(OutputDestination, RegularFilesNewPathsAndLinksToThemAreWritten) {
  TempDir dir;
  write_text(dir / "old.txt", "old");
  fs::create_symlink(dir / "old.txt", dir / "link.txt");
  write_atomically(dir / "link.txt", "via link");
  write_atomically(dir / "new.txt", "new");
  EXPECT_EQ(read_text(dir / "old.txt"), "via link");
  EXPECT_TRUE(fs::is_symlink(dir / "link.txt"));
  EXPECT_EQ(read_text(dir / "new.txt"), "new");
}

TEST(OutputDestination, TheCliRefusesAFifoAndALinkToADeviceBeforeAnyWork) {
  TempDir dir;
  ASSERT_EQ(::mkfifo((dir / "pipe.png").c_str(), 0644), 0);
  fs::create_symlink("/dev/null", dir / "null.exr");
  for (const char* out : {"pipe.png", "null.exr"}) {
    SCOPED_TRACE(out);
    // Without the check, writing into the FIFO would block the run until a reader came.
    const RunResult r = run_ao(std::string("render -o ") + out + " --width 16 --height 16 --spp 2 -q", dir.path());
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("not a regular file"), std::string::npos) << r.err;
  }
  EXPECT_TRUE(fs::is_fifo(dir / "pipe.png"));
  EXPECT_TRUE(fs::is_symlink(dir / "null.exr"));
  EXPECT_EQ(dir.file_count(), 2);
}

TEST(OutputCommit, ARenameFailingDuringCommitLeavesEveryOldOutputInPlace) {
  for (int failing = 0; failing < 3; ++failing) {
    SCOPED_TRACE("rename " + std::to_string(failing) + " fails");
    TempDir dir;
    write_text(dir / "a.txt", "old a");
    write_text(dir / "c.txt", "old c");  // b.txt is new
    {
      OutputSet outputs;
      for (const char* name : {"a.txt", "b.txt", "c.txt"})
        outputs.write(dir / name, [&] { write_atomically(dir / name, std::string("new ") + name); });
      detail::fail_commit_rename_for_testing(failing, EIO);
      expect_one_line_error<SystemError>([&] { outputs.commit(); }, dir / (std::string(1, static_cast<char>('a' + failing)) + ".txt"),
                                         "no output was replaced");
    }
    EXPECT_EQ(read_text(dir / "a.txt"), "old a");
    EXPECT_FALSE(fs::exists(dir / "b.txt"));
    EXPECT_EQ(read_text(dir / "c.txt"), "old c");
    EXPECT_EQ(dir.file_count(), 2) << "a temporary or backup file was left";
  }
}

TEST(OutputCommit, ARealRenameFailureRollsBackTheOutputsAlreadyReplaced) {
  TempDir dir;
  write_text(dir / "a.txt", "old a");
  write_text(dir / "b.txt", "old b");
  {
    OutputSet outputs;
    outputs.write(dir / "a.txt", [&] { write_atomically(dir / "a.txt", "new a"); });
    outputs.write(dir / "b.txt", [&] { write_atomically(dir / "b.txt", "new b"); });
    // Between the writes and the commit, b.txt becomes a folder that is not empty: renaming a
    // file over it fails (EISDIR) after a.txt was replaced.
    fs::remove(dir / "b.txt");
    fs::create_directory(dir / "b.txt");
    write_text(dir / "b.txt" / "keep", "k");
    EXPECT_THROW(outputs.commit(), SystemError);
  }
  EXPECT_EQ(read_text(dir / "a.txt"), "old a");
  EXPECT_EQ(read_text(dir / "b.txt" / "keep"), "k");
  EXPECT_EQ(dir.file_count(), 2);
}

TEST(OutputCommit, SuccessfulCommitLeavesNoBackup) {
  TempDir dir;
  write_text(dir / "a.txt", "old a");
  OutputSet outputs;
  outputs.write(dir / "a.txt", [&] { write_atomically(dir / "a.txt", "new a"); });
  outputs.write(dir / "b.txt", [&] { write_atomically(dir / "b.txt", "new b"); });
  outputs.commit();
  EXPECT_EQ(read_text(dir / "a.txt"), "new a");
  EXPECT_EQ(read_text(dir / "b.txt"), "new b");
  EXPECT_EQ(dir.file_count(), 2);
}

TEST(StaleTemporaries, ThoseOfKilledRunsAreRemovedOthersAreKept) {
  TempDir dir;
  const auto an_hour_ago = fs::file_time_type::clock::now() - std::chrono::hours(1);
  const std::string dead = std::to_string(dead_pid()), alive = std::to_string(::getppid());
  const fs::path stale = dir / (".out.tmp-" + dead + "-0.png"), live = dir / (".out.tmp-" + alive + "-3.png"),
                 other = dir / (".other.tmp-" + dead + "-0.png"), young = dir / (".out.tmp-" + dead + "-1.png"), user = dir / ".out.tmp-notes.png";
  for (const fs::path& p : {stale, live, other, user}) write_text(p, "x");
  for (const fs::path& p : {stale, live, other, user}) fs::last_write_time(p, an_hour_ago);
  write_text(young, "written after this process started");
  OutputSet outputs;
  outputs.add_output(dir / "out.png", "-o");
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(live)) << "its process still runs";
  EXPECT_TRUE(fs::exists(other)) << "another output's";
  EXPECT_TRUE(fs::exists(young)) << "newer than this run";
  EXPECT_TRUE(fs::exists(user)) << "not a name ao makes";
  EXPECT_EQ(remove_stale_temporaries(dir / "out.png"), 0);
}

TEST(StaleTemporaries, ALaterCliRunRemovesWhatAKilledRunLeft) {
  TempDir dir;
  const fs::path stale = dir / (".demo.tmp-" + std::to_string(dead_pid()) + "-0.png");
  write_text(stale, "half a PNG");
  fs::last_write_time(stale, fs::file_time_type::clock::now() - std::chrono::minutes(5));
  const RunResult r = run_ao("render -o demo.png --width 16 --height 16 --spp 2 -q", dir.path());
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_EQ(dir.file_count(), 1);
}

TEST(FullDisk, TheErrorSaysTheDiskIsFull) {
  // A 64 KiB tmpfs in a private mount namespace (unprivileged through a user namespace): a real
  // ENOSPC, whatever the writer's library makes of it.
  TempDir dir;
  fs::create_directory(dir / "small");
  const std::string probe = "unshare -rm sh -c 'mount -t tmpfs -o size=64k none " + (dir / "small").string() + "' >/dev/null 2>&1";
  if (std::system(probe.c_str()) != 0) GTEST_SKIP() << "a tmpfs cannot be mounted in user and mount namespaces here (unshare -rm)";
  const RunResult r = run_ao_under("unshare -rm sh -c 'mount -t tmpfs -o size=64k none small && (head -c 1000000 /dev/zero > small/fill) 2>/dev/null;"
                                   " exec \"$0\" \"$@\"'",
                                   "render -o small/big.exr --width 512 --height 512 --spp 1 -q", dir.path());
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("big.exr: cannot write: the disk is full"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

}  // namespace
}  // namespace ao::test
