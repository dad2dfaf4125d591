// SPDX-License-Identifier: Apache-2.0
// Outputs as one transaction (SPEC, "Behaviour on bad input"): a run's outputs are renamed into
// place only when all were written, an output that names an input or another output is refused
// before anything is written, and temporary files never outlive a failure or a signal. Issue 27:
// only regular files or new paths are written (a FIFO, a device node or a symbolic link to one is
// refused before any work); a rename failing during commit leaves every previous output in place;
// temporary files of killed runs are removed; a full disk says so.
#include "ao/io/output_set.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "ao/core/error.h"
#include "ao/io/atomic_file.h"
#include "ao/io/commit_journal.h"
#include "support/errors.h"
#include "support/run.h"

namespace ao::test {
namespace {

namespace fs = std::filesystem;

void write_atomically(const fs::path& path, const std::string& text) {
  write_file_atomically(path, [&](const fs::path& temp) { write_text(temp, text); });
}

// Names in `dir` that start with '.' (the temporary files of write_file_atomically).
int hidden_files(const fs::path& dir) {
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir)) n += e.path().filename().string().rfind('.', 0) == 0;
  return n;
}

TEST(OutputSet, NothingIsRenamedBeforeCommitAndEverythingAfter) {
  TempDir dir;
  write_text(dir / "a.txt", "old a");
  OutputSet outputs;
  outputs.add_output(dir / "a.txt", "-o");
  outputs.add_output(dir / "b.txt", "--other");
  outputs.write(dir / "a.txt", [&] { write_atomically(dir / "a.txt", "new a"); });
  outputs.write(dir / "b.txt", [&] { write_atomically(dir / "b.txt", "new b"); });
  EXPECT_EQ(read_text(dir / "a.txt"), "old a");
  EXPECT_FALSE(fs::exists(dir / "b.txt"));
  EXPECT_EQ(read_text(outputs.staged(dir / "a.txt")), "new a");  // readable before commit
  outputs.commit();
  EXPECT_EQ(read_text(dir / "a.txt"), "new a");
  EXPECT_EQ(read_text(dir / "b.txt"), "new b");
  EXPECT_EQ(hidden_files(dir.path()), 0);
}

TEST(OutputSet, LateFailureLeavesEveryOutputAsItWasAndNoTemporaryFile) {
  TempDir dir;
  write_text(dir / "a.txt", "old a");
  write_text(dir / "b.txt", "old b");
  {
    OutputSet outputs;
    outputs.add_output(dir / "a.txt", "-o");
    outputs.add_output(dir / "b.txt", "--other");
    outputs.write(dir / "a.txt", [&] { write_atomically(dir / "a.txt", "new a"); });
    EXPECT_THROW(outputs.write(dir / "b.txt",
                               [&] {
                                 write_file_atomically(dir / "b.txt", [](const fs::path& temp) {
                                   write_text(temp, "half");
                                   throw SystemError("disk full");
                                 });
                               }),
                 SystemError);
  }  // destroyed without commit, as when the error leaves the run
  EXPECT_EQ(read_text(dir / "a.txt"), "old a");
  EXPECT_EQ(read_text(dir / "b.txt"), "old b");
  EXPECT_EQ(dir.file_count(), 2);
}

TEST(OutputSet, OutputThatNamesAnInputIsRefusedWhateverTheSpelling) {
  TempDir dir;
  const fs::path in = dir.write("in.ply", "ply");
  fs::create_directory(dir / "sub");
  fs::create_symlink(in, dir / "link.ply");
  fs::create_hard_link(in, dir / "hard.ply");
  for (const fs::path& out : {in, dir / "sub" / ".." / "in.ply", dir / "link.ply", dir / "hard.ply"}) {
    OutputSet outputs;
    outputs.add_input(in, "the mesh");
    expect_one_line_error<InputError>([&] { outputs.add_output(out, "--per-vertex"); }, out, "is the input of the mesh");
  }
  // Declared the other way round: the input is refused.
  OutputSet outputs;
  outputs.add_output(dir / "link.ply", "--per-vertex");
  expect_one_line_error<InputError>([&] { outputs.add_input(in, "the mesh"); }, dir / "link.ply", "is the input of the mesh");
  EXPECT_EQ(read_text(in), "ply");
}

TEST(OutputSet, TwoOutputsOfOneFileAreRefused) {
  TempDir dir;
  OutputSet outputs;
  outputs.add_output(dir / "x.png", "-o");
  expect_one_line_error<InputError>([&] { outputs.add_output(dir / "." / "x.png", "--shaded"); }, dir / "x.png", "both -o and --shaded");
}

TEST(OutputSet, MissingFolderAndDirectoryTargetAreRefusedAtDeclaration) {
  TempDir dir;
  OutputSet outputs;
  expect_one_line_error<InputError>([&] { outputs.add_output(dir / "nowhere" / "x.png", "-o"); }, dir / "nowhere" / "x.png", "does not exist");
  fs::create_directory(dir / "d.png");
  expect_one_line_error<InputError>([&] { outputs.add_output(dir / "d.png", "-o"); }, dir / "d.png", "directory");
}

TEST(OutputSet, NewFolderAppearsOnlyWithItsOutputs) {
  TempDir dir;
  {
    OutputSet outputs;
    outputs.add_directory(dir / "out", "--out-dir");
    outputs.add_output(dir / "out" / "t.md", "--out-dir");
    outputs.write(dir / "out" / "t.md", [&] { write_atomically(dir / "out" / "t.md", "table"); });
  }  // failed run: the folder it created is gone
  EXPECT_FALSE(fs::exists(dir / "out"));
  OutputSet outputs;
  outputs.add_directory(dir / "out", "--out-dir");
  outputs.write(dir / "out" / "t.md", [&] { write_atomically(dir / "out" / "t.md", "table"); });
  outputs.commit();
  EXPECT_EQ(read_text(dir / "out" / "t.md"), "table");
  EXPECT_EQ(hidden_files(dir.path()), 0);
}

// A child process stages one output, then is killed by `sig` while the temporary file exists: the
// handler of remove_temporaries_on_signals removes it, and the child dies of that signal.
void expect_signal_removes_temporaries(int sig) {
  TempDir dir;
  write_text(dir / "a.txt", "old a");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    remove_temporaries_on_signals();
    OutputSet outputs;
    outputs.add_directory(dir / "new", "--out-dir");
    outputs.write(dir / "a.txt", [&] { write_atomically(dir / "a.txt", "new a"); });
    outputs.write(dir / "new" / "b.txt", [&] { write_atomically(dir / "new" / "b.txt", "new b"); });
    ::raise(sig);
    ::_exit(0);  // not reached
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status)) << status;
  EXPECT_EQ(WTERMSIG(status), sig);
  EXPECT_EQ(read_text(dir / "a.txt"), "old a");
  EXPECT_FALSE(fs::exists(dir / "new"));  // its temporary file, then the folder created for it
  EXPECT_EQ(dir.file_count(), 1);
}

TEST(OutputSet, SigtermRemovesTheTemporaryFiles) { expect_signal_removes_temporaries(SIGTERM); }
TEST(OutputSet, SigintRemovesTheTemporaryFiles) { expect_signal_removes_temporaries(SIGINT); }

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
  // A file's time comes from the kernel's coarse clock, which can lag the clock read at start-up
  // by a few milliseconds; set it explicitly so the test does not depend on that granularity.
  fs::last_write_time(young, fs::file_time_type::clock::now() + std::chrono::seconds(1));
  OutputSet outputs;
  outputs.add_output(dir / "out.png", "-o");
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(live)) << "its process still runs";
  EXPECT_TRUE(fs::exists(other)) << "another output's";
  EXPECT_TRUE(fs::exists(young)) << "newer than this run";
  EXPECT_TRUE(fs::exists(user)) << "not a name ao makes";
  EXPECT_EQ(remove_stale_temporaries(dir / "out.png"), 0);
}

TEST(StaleTemporaries, AbandonedOnesAreRemovedWheneverWritten) {
  // A batch task rerun after its worker was killed: the temporary files of other processes for
  // its own output go, also those written after this process started; other names stay.
  TempDir dir;
  const std::string dead = std::to_string(dead_pid()), alive = std::to_string(::getppid());
  const fs::path young = dir / (".out.tmp-" + dead + "-1.png"), live = dir / (".out.tmp-" + alive + "-3.png"),
                 other = dir / (".other.tmp-" + dead + "-0.png"), user = dir / ".out.tmp-notes.png";
  for (const fs::path& p : {young, live, other, user}) write_text(p, "x");
  EXPECT_EQ(remove_abandoned_temporaries(dir / "out.png"), 2);
  EXPECT_FALSE(fs::exists(young));
  EXPECT_FALSE(fs::exists(live)) << "the caller owns the output: another writer of it is not live";
  EXPECT_TRUE(fs::exists(other)) << "another output's";
  EXPECT_TRUE(fs::exists(user)) << "not a name ao makes";
}

// In a forked child: a commit of `dest` ("old <tag>" -> "new <tag>") stopped after its rename, as a
// worker killed there leaves it: the journal written, `dest` renamed into place, its previous file
// kept by a hard link. The child holds the journal returned and ends with _exit, which leaves it.
std::unique_ptr<detail::CommitJournal> commit_halfway(const fs::path& dest, const std::string& tag) {
  write_text(dest, "old " + tag);
  const fs::path dir = dest.parent_path(), pid = std::to_string(::getpid());
  const fs::path temp = dir / ("." + tag + ".tmp-" + pid.string() + "-1.png"), backup = dir / ("." + tag + ".keep-" + pid.string());
  write_text(temp, "new " + tag);
  fs::create_hard_link(dest, backup);
  auto journal = std::make_unique<detail::CommitJournal>(std::vector<detail::JournalEntry>{{dest, temp, backup}});
  fs::rename(temp, dest);
  return journal;
}

// A batch's tasks share their output folder: the cleanup a task does for its own output must not
// undo another worker's commit that is renaming its outputs at that moment (seen as a forced rerun
// whose grid1 map and record came back with the previous run's settings, because the task of
// grid2 rolled grid1's live commit back). Only a commit that lists the owned output is undone.
TEST(StaleTemporaries, AnOwnedOutputsCleanupLeavesOtherLiveCommitsAlone) {
  TempDir dir;
  const fs::path b = dir / "b.png";
  int ready[2], release[2];
  ASSERT_EQ(::pipe(ready), 0);
  ASSERT_EQ(::pipe(release), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // Another worker, half way through its commit of b.png: the journal written, b.png renamed
    // into place, its previous file kept by a hard link. It waits there until released.
    const auto journal = commit_halfway(b, "b");
    char c = 'r';
    if (::write(ready[1], &c, 1) != 1 || ::read(release[0], &c, 1) != 1) ::_exit(2);
    ::_exit(0);  // leaves the journal, as a worker killed here would
  }
  char c = 0;
  ASSERT_EQ(::read(ready[0], &c, 1), 1);
  // And a commit of c.png whose process is gone (killed after its rename): that one is undone.
  const fs::path cfile = dir / "c.png";
  const pid_t gone = ::fork();
  ASSERT_GE(gone, 0);
  if (gone == 0) {
    const auto journal = commit_halfway(cfile, "c");
    ::_exit(0);  // the journal stays, as SIGKILL would leave it
  }
  int gone_status = 0;
  ASSERT_EQ(::waitpid(gone, &gone_status, 0), gone);
  for (const auto& e : fs::directory_iterator(dir.path()))
    if (e.path().filename().string().find(".journal") != std::string::npos && e.path().filename().string().find(std::to_string(gone)) != std::string::npos)
      fs::last_write_time(e.path(), fs::file_time_type::clock::now() - std::chrono::hours(1));  // begun before this process
  remove_abandoned_temporaries(dir / "a.png");
  EXPECT_EQ(read_text(cfile), "old c") << "a commit whose process is gone is rolled back";
  EXPECT_EQ(read_text(b), "new b") << "another output's commit, live, was rolled back";
  EXPECT_EQ(hidden_files(dir.path()), 2) << "its journal and the link to its previous file stay";
  // The owner of b.png, rerunning its task, undoes the commit (live or not, it was abandoned).
  remove_abandoned_temporaries(b);
  EXPECT_EQ(read_text(b), "old b");
  EXPECT_EQ(hidden_files(dir.path()), 0);
  ASSERT_EQ(::write(release[1], &c, 1), 1);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  for (int fd : {ready[0], ready[1], release[0], release[1]}) ::close(fd);
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
