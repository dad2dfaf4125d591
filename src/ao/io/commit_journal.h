// SPDX-License-Identifier: Apache-2.0
// The journal of a multi-output commit (OutputSet::commit), so that a run killed between two
// renames (SIGKILL, a power cut) leaves nothing mixed: before the first rename, the commit writes
// in the folder of each output a hidden journal listing every output, its staged file and the
// hard link that keeps its previous file; the next run that writes into one of those folders
// finds the journal of a process that is gone and rolls the commit back, so every output is as it
// was before the killed run. A commit that ends (renamed or rolled back) removes its journal.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace ao::detail {

/// One output of a commit: where it goes, the staged (temporary) file, and the hard link that
/// keeps the file it replaces (empty: there was none).
struct JournalEntry {
  std::filesystem::path destination, temp, backup;
};

/// The journal of one commit, written by the constructor (in the folder of each destination,
/// flushed to disk with its folder before it returns) and removed by remove() or the destructor.
/// SystemError, naming the first destination, when it cannot be written: then nothing has been
/// renamed yet, and the commit is abandoned.
class CommitJournal {
 public:
  explicit CommitJournal(const std::vector<JournalEntry>& entries);
  ~CommitJournal();
  CommitJournal(const CommitJournal&) = delete;
  CommitJournal& operator=(const CommitJournal&) = delete;
  /// Removes the journal's files (the commit is over).
  void remove();

 private:
  std::vector<std::filesystem::path> files_;
};

/// Rolls back the commits journaled in `folder` whose process no longer runs on this machine and
/// which began before this process started: each destination gets its previous file back (or is
/// removed when it had none), staged files and links are removed, then the journals. With
/// `owned_output`, it also rolls back every commit of another process, live or not, on this
/// machine or another, whose journal lists that output: the caller owns it (a batch's task rerun
/// after the worker that held it was lost), so such a commit was abandoned; the live commits of
/// other outputs in the folder are left alone, since their writers may be running. Returns how
/// many commits it rolled back; never throws.
int recover_interrupted_commits(const std::filesystem::path& folder, const std::filesystem::path& owned_output = {});

/// True when `name` is the name of a journal file (hidden, ".ao-commit-<pid>-<hex>.journal").
bool is_journal_name(const std::string& name);

}  // namespace ao::detail
