// Outputs as one transaction (SPEC, "Behaviour on bad input"): a run's outputs are renamed into
// place only when all were written, an output that names an input or another output is refused
// before anything is written, and temporary files never outlive a failure or a signal.
#include "ao/io/output_set.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <stdexcept>

#include "ao/core/error.h"
#include "ao/io/atomic_file.h"
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

TEST(ScratchFile, IsRemovedWithItsOwner) {
  TempDir dir;
  {
    const ScratchFile scratch(dir / "s.png");
    write_text(scratch.path(), "x");
    EXPECT_TRUE(fs::exists(dir / "s.png"));
  }
  EXPECT_EQ(dir.file_count(), 0);
}

}  // namespace
}  // namespace ao::test
