// SPDX-License-Identifier: Apache-2.0
#include "ao/io/output_set.h"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <optional>
#include <system_error>
#include <utility>

#include "ao/core/error.h"
#include "ao/io/asset_path.h"
#include "ao/io/commit_journal.h"

namespace ao {

namespace fs = std::filesystem;

namespace {

fs::path resolve(const fs::path& p) { return resolved_path(p); }

// The same file: the same path once resolved, or (when both exist) the same inode, which also
// catches hard links and bind mounts.
bool same_file(const fs::path& a_resolved, const fs::path& b_resolved) {
  if (a_resolved == b_resolved) return true;
  std::error_code ec;
  const bool equal = fs::equivalent(a_resolved, b_resolved, ec);
  return !ec && equal;
}

fs::path parent_of(const fs::path& resolved) { return resolved.has_parent_path() ? resolved.parent_path() : fs::path("."); }

}  // namespace

OutputSet::~OutputSet() {
  std::error_code ec;
  if (!committed_)
    for (const Staged& s : staged_) fs::remove(s.temp, ec);
  staged_.clear();  // unregisters the temporary files before their folders
  if (!committed_)
    for (auto it = directories_.rbegin(); it != directories_.rend(); ++it)
      if (it->created) fs::remove(it->path, ec);  // only if empty: never a user's file
}

OutputSet::Named OutputSet::name(const fs::path& path, std::string what) const { return {path, resolve(path), std::move(what)}; }

const OutputSet::Directory* OutputSet::directory_for(const fs::path& resolved_parent) const {
  for (const Directory& d : directories_)
    if (resolve(d.path) == resolved_parent) return &d;
  return nullptr;
}

void OutputSet::add_input(const fs::path& path, std::string what) {
  std::error_code ec;
  if (path.empty() || !fs::exists(path, ec)) return;
  Named in = name(path, std::move(what));
  for (const Named& out : outputs_)
    if (same_file(out.resolved, in.resolved))
      throw InputError(out.path.string() + ": the output of " + out.what + " is the input of " + in.what + "; give the output another name");
  inputs_.push_back(std::move(in));
}

void OutputSet::add_output(const fs::path& path, std::string what) {
  if (path.empty() || !path.has_filename()) throw InputError(what + ": '" + path.string() + "' names no file");
  Named out = name(path, std::move(what));
  for (const Named& in : inputs_)
    if (same_file(out.resolved, in.resolved))
      throw InputError(path.string() + ": the output of " + out.what + " is the input of " + in.what + "; give the output another name");
  for (const Named& other : outputs_)
    if (same_file(out.resolved, other.resolved)) {
      if (other.what == out.what) return;
      throw InputError(path.string() + ": named as the output of both " + other.what + " and " + out.what + "; give each output its own name");
    }
  std::error_code ec;
  if (fs::is_directory(out.resolved, ec)) throw InputError(path.string() + ": " + out.what + " names a directory, not a file");
  check_output_destination(path, out.what);
  const fs::path dir = parent_of(out.resolved);
  if (!directory_for(dir)) {
    if (!fs::exists(dir, ec)) throw InputError(path.string() + ": folder '" + dir.string() + "' does not exist");
    if (!fs::is_directory(dir, ec)) throw InputError(path.string() + ": '" + dir.string() + "' is not a directory");
  }
  remove_stale_temporaries(out.resolved);
  outputs_.push_back(std::move(out));
}

void OutputSet::add_directory(const fs::path& dir, std::string what) {
  std::error_code ec;
  const fs::path resolved = resolve(dir);
  if (directory_for(resolved)) return;
  Directory d;
  d.path = resolved;
  if (fs::exists(resolved, ec)) {
    if (!fs::is_directory(resolved, ec)) throw InputError(dir.string() + ": " + what + " exists and is not a directory");
  } else {
    const fs::path parent = parent_of(resolved);
    if (!fs::is_directory(parent, ec)) throw InputError(dir.string() + ": " + what + ": the parent folder '" + parent.string() + "' does not exist");
    d.create = true;
  }
  for (const Named& in : inputs_)
    if (same_file(resolved, in.resolved)) throw InputError(dir.string() + ": " + what + " is the input of " + in.what);
  directories_.push_back(std::move(d));
}

void OutputSet::write(const fs::path& path, const std::function<void()>& write, std::string what) {
  const fs::path resolved = resolve(path);
  bool declared = false;
  for (const Named& out : outputs_) declared = declared || out.resolved == resolved;
  if (!declared) add_output(path, std::move(what));
  for (Directory& d : directories_)
    if (d.create && !d.created && d.path == parent_of(resolved)) {
      // Registered before it exists, so that a signal after the mkdir finds it.
      d.registration = TemporaryRegistration(d.path, /*directory=*/true);
      std::error_code ec;
      if (!fs::create_directory(d.path, ec) && ec) throw SystemError(d.path.string() + ": cannot create the folder: " + ec.message());
      d.created = true;
    }
  const detail::DeferredRenames defer([this](const fs::path& temp, const fs::path& destination, TemporaryRegistration registration) {
    for (Staged& s : staged_)
      if (s.destination == destination) {  // written twice in one run: the later content wins
        std::error_code ec;
        fs::remove(s.temp, ec);
        s.temp = temp;
        s.registration = std::move(registration);
        return;
      }
    staged_.push_back({temp, destination, std::move(registration)});
  });
  write();
}

std::vector<fs::path> OutputSet::written() const {
  std::vector<fs::path> out;
  for (const Staged& s : staged_) out.push_back(s.destination);
  return out;
}

fs::path OutputSet::staged(const fs::path& path) const {
  const fs::path resolved = resolve(path);
  for (const Staged& s : staged_)
    if (resolve(s.destination) == resolved) return s.temp;
  throw InputError(path.string() + ": nothing was written for this output yet");
}

namespace {

/// SIGINT, SIGTERM and SIGHUP held back while it lives (delivered when it ends): their handlers
/// remove registered temporary files, which in the middle of a commit include the links that keep
/// the previous outputs. The commit completes or rolls back first; then the signal ends the run.
class HeldSignals {
 public:
  HeldSignals() {
    sigset_t set;
    sigemptyset(&set);
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&set, sig);
    ::pthread_sigmask(SIG_BLOCK, &set, &old_);
  }
  ~HeldSignals() { ::pthread_sigmask(SIG_SETMASK, &old_, nullptr); }
  HeldSignals(const HeldSignals&) = delete;
  HeldSignals& operator=(const HeldSignals&) = delete;

 private:
  sigset_t old_;
};

}  // namespace

void OutputSet::commit() {
  // Each destination that holds a file keeps it under a hidden name (a hard link: the same file,
  // no copy; a copy where the file system has no hard links) until every rename succeeded, so a
  // rename that fails puts back the files already replaced and removes the new ones. With two
  // outputs or more, a journal listing them all is on disk before the first rename, so that a run
  // killed between two renames is rolled back by the next run (commit_journal.h).
  const HeldSignals held;
  struct Replaced {
    fs::path destination, backup;  ///< backup empty: there was no file before
    TemporaryRegistration registration;
  };
  std::vector<Replaced> backups;
  std::error_code ec;
  std::size_t renamed = 0;
  const auto undo = [&] {
    for (std::size_t k = renamed; k-- > 0;) {
      if (backups[k].backup.empty()) fs::remove(backups[k].destination, ec);
      else fs::rename(backups[k].backup, backups[k].destination, ec);
    }
    for (const Replaced& r : backups)
      if (!r.backup.empty()) fs::remove(r.backup, ec);
    for (const Staged& s : staged_) fs::remove(s.temp, ec);
  };
  for (const Staged& s : staged_) {
    Replaced r{s.destination, {}, {}};
    if (fs::is_regular_file(fs::symlink_status(s.destination, ec))) {
      r.backup = detail::temporary_path_for(s.destination);
      r.registration = TemporaryRegistration(r.backup);
      if (::link(s.destination.c_str(), r.backup.c_str()) != 0) {
        std::error_code copy_ec;
        if (!fs::copy_file(s.destination, r.backup, fs::copy_options::overwrite_existing, copy_ec)) {
          backups.push_back(std::move(r));
          undo();
          throw SystemError(s.destination.string() + ": cannot keep the previous file while the outputs are renamed: " + copy_ec.message() +
                            "; no output was replaced");
        }
      }
    }
    backups.push_back(std::move(r));
  }
  std::optional<detail::CommitJournal> journal;
  if (staged_.size() > 1) {
    std::vector<detail::JournalEntry> entries;
    for (std::size_t i = 0; i < staged_.size(); ++i) entries.push_back({staged_[i].destination, staged_[i].temp, backups[i].backup});
    try {
      journal.emplace(entries);
    } catch (...) {
      undo();
      throw;
    }
  }
  for (std::size_t i = 0; i < staged_.size(); ++i) {
    Staged& s = staged_[i];
    const int injected = detail::commit_rename_fault(i);
    if (injected != 0) ec = std::error_code(injected, std::generic_category());
    else fs::rename(s.temp, s.destination, ec);
    if (ec) {
      const std::string why = ec == std::errc::no_space_on_device ? "the disk is full" : ec.message();
      undo();
      throw SystemError(s.destination.string() + ": cannot rename the temporary file into place: " + why + "; no output was replaced");
    }
    s.registration = TemporaryRegistration();
    ++renamed;
  }
  for (const Replaced& r : backups)
    if (!r.backup.empty()) fs::remove(r.backup, ec);
  if (journal) journal->remove();
  for (Directory& d : directories_) d.registration = TemporaryRegistration();
  committed_ = true;
}

namespace detail {
namespace {
std::atomic<int> g_fault_index{-1};
std::atomic<int> g_fault_errno{0};
}  // namespace

void fail_commit_rename_for_testing(int index, int error) {
  g_fault_errno.store(error);
  g_fault_index.store(index);
}

int commit_rename_fault(std::size_t index) {
  if (g_fault_index.load() < 0 || static_cast<std::size_t>(g_fault_index.load()) != index) return 0;
  g_fault_index.store(-1);
  return g_fault_errno.load();
}
}  // namespace detail

std::vector<fs::path> OutputSet::outputs() const {
  std::vector<fs::path> paths;
  for (const Named& out : outputs_) paths.push_back(out.path);
  return paths;
}

}  // namespace ao
