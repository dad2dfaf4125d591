// SPDX-License-Identifier: Apache-2.0
#include "ao/io/commit_journal.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <fstream>
#include <sstream>
#include <system_error>

#include "ao/core/error.h"
#include "ao/io/atomic_file.h"

namespace ao::detail {

namespace fs = std::filesystem;

namespace {

// The format: a first line naming it, one line per output ("<destination>\t<temp>\t<backup>",
// absolute paths; OutputSet refuses names with control characters), and a last line "end". A
// journal without its last line was cut while being written, before any rename.
constexpr const char* kJournalHeader = "ao commit journal 1";
constexpr const char* kJournalEnd = "end";
constexpr const char* kJournalPrefix = ".ao-commit-";
constexpr const char* kJournalSuffix = ".journal";

/// When this process started (static initialisation): journals written after it may be a live
/// run's on another machine sharing the folder.
const fs::file_time_type g_process_start = fs::file_time_type::clock::now();

fs::path folder_of(const fs::path& p) { return p.has_parent_path() ? p.parent_path() : fs::path("."); }

/// `p` absolute, with ".", ".." and the links of its folders resolved: two names of one output
/// compare equal (a journal holds absolute paths; a caller may name the output relatively).
fs::path same_file_key(const fs::path& p) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(p, ec);
  if (ec) return p.lexically_normal();
  const fs::path folder = fs::weakly_canonical(folder_of(absolute), ec);
  return ec ? absolute.lexically_normal() : folder / absolute.filename();
}

/// The pid in a journal's name, or -1.
long journal_pid(const std::string& name) {
  if (!is_journal_name(name)) return -1;
  const std::string middle = name.substr(std::string(kJournalPrefix).size());
  try {
    return std::stol(middle.substr(0, middle.find('-')));
  } catch (const std::exception&) {
    return -1;
  }
}

// Writes `text` to the new file `path` (O_EXCL, O_NOFOLLOW) and flushes it and its folder to disk.
bool write_synced(const fs::path& path, const std::string& text) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0) return false;
  bool ok = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size()) && ::fsync(fd) == 0;
  ok = ::close(fd) == 0 && ok;
  const int dir = ::open(folder_of(path).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);  // the journal's name must survive a power cut before the first rename
    ::close(dir);
  }
  return ok;
}

struct Journal {
  std::vector<JournalEntry> entries;
  bool complete = false;
};

Journal read_journal(const fs::path& path) {
  Journal j;
  std::ifstream in(path, std::ios::binary);
  std::string line;
  if (!std::getline(in, line) || line != kJournalHeader) return j;
  while (std::getline(in, line)) {
    if (line == kJournalEnd) {
      j.complete = true;
      break;
    }
    std::istringstream fields(line);
    std::string destination, temp, backup;
    std::getline(fields, destination, '\t');
    std::getline(fields, temp, '\t');
    std::getline(fields, backup, '\t');
    if (destination.empty() || temp.empty()) return {};  // damaged: leave everything as it is
    j.entries.push_back({destination, temp, backup});
  }
  return j;
}

// Undoes one journaled commit: the outputs renamed into place get their previous files back (or
// go, when there was none), and what was staged is removed; last, the journal in every folder.
void roll_back(const fs::path& journal, const Journal& j) {
  std::error_code ec;
  for (auto it = j.entries.rbegin(); it != j.entries.rend(); ++it) {
    if (j.complete) {
      if (!it->backup.empty() && fs::exists(fs::symlink_status(it->backup, ec))) {
        // The previous file, back in place. When the rename had not happened the two names are
        // one file and rename() changes nothing: the link is removed below.
        fs::rename(it->backup, it->destination, ec);
      } else if (it->backup.empty() && !fs::exists(fs::symlink_status(it->temp, ec))) {
        fs::remove(it->destination, ec);  // new, and renamed into place: there was nothing before
      }
    }
    fs::remove(it->temp, ec);
    if (!it->backup.empty()) fs::remove(it->backup, ec);
  }
  for (const JournalEntry& e : j.entries) fs::remove(folder_of(e.destination) / journal.filename(), ec);
  fs::remove(journal, ec);
}

}  // namespace

bool is_journal_name(const std::string& name) {
  const std::string prefix = kJournalPrefix, suffix = kJournalSuffix;
  if (!name.starts_with(prefix) || !name.ends_with(suffix) || name.size() <= prefix.size() + suffix.size()) return false;
  const std::string middle = name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());  // "<pid>-<hex>"
  const std::size_t dash = middle.find('-');
  return dash != 0 && dash != std::string::npos && middle.substr(0, dash).find_first_not_of("0123456789") == std::string::npos &&
         middle.substr(dash + 1).find_first_not_of("0123456789abcdef") == std::string::npos && dash + 1 < middle.size();
}

CommitJournal::CommitJournal(const std::vector<JournalEntry>& entries) {
  std::string text = std::string(kJournalHeader) + "\n";
  for (const JournalEntry& e : entries)
    text += fs::absolute(e.destination).string() + "\t" + fs::absolute(e.temp).string() + "\t" + (e.backup.empty() ? std::string() : fs::absolute(e.backup).string()) + "\n";
  text += std::string(kJournalEnd) + "\n";
  const std::string name = kJournalPrefix + std::to_string(::getpid()) + "-" + random_suffix() + kJournalSuffix;
  for (const JournalEntry& e : entries) {
    const fs::path file = folder_of(e.destination) / name;
    if (std::find(files_.begin(), files_.end(), file) != files_.end()) continue;
    if (!write_synced(file, text)) {
      const int err = errno;
      remove();
      throw SystemError(entries.front().destination.string() + ": cannot write the journal of the outputs' commit in '" + folder_of(e.destination).string() +
                        "': " + std::generic_category().message(err) + "; no output was replaced");
    }
    files_.push_back(file);
  }
}

CommitJournal::~CommitJournal() { remove(); }

void CommitJournal::remove() {
  std::error_code ec;
  for (const fs::path& f : files_) fs::remove(f, ec);
  files_.clear();
}

int recover_interrupted_commits(const fs::path& folder, const fs::path& owned_output) {
  std::error_code ec;
  const fs::path owned = owned_output.empty() ? fs::path() : same_file_key(owned_output);
  std::vector<std::pair<fs::path, Journal>> abandoned;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const long pid = journal_pid(name);
    if (pid <= 0 || pid == ::getpid()) continue;
    // Gone: its process no longer runs here (EPERM: one we may not signal, not ours to undo), and
    // it began before this process, so it is not a live run's on another machine.
    std::error_code file_ec;
    const bool gone = ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH && it->last_write_time(file_ec) < g_process_start && !file_ec;
    if (!gone && owned.empty()) continue;
    Journal j = read_journal(it->path());
    // A live writer's commit in the same folder (a batch's tasks share their output folder) is
    // left alone unless it lists the output the caller owns.
    if (!gone && std::none_of(j.entries.begin(), j.entries.end(), [&](const JournalEntry& e) { return same_file_key(e.destination) == owned; })) continue;
    abandoned.emplace_back(it->path(), std::move(j));
  }
  for (const auto& [path, j] : abandoned) roll_back(path, j);
  return static_cast<int>(abandoned.size());
}

}  // namespace ao::detail
