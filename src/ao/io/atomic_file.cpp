// SPDX-License-Identifier: Apache-2.0
#include "ao/io/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/random.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <system_error>

#include "ao/core/error.h"
#include "ao/io/commit_journal.h"

namespace ao {

namespace fs = std::filesystem;

namespace {

/// "the file size limit (ulimit -f) of N bytes is reached": what a write past RLIMIT_FSIZE says.
std::string file_size_limit_text() {
  struct rlimit limit {};
  if (::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
    return "the file size limit (ulimit -f) of " + std::to_string(limit.rlim_cur) + " bytes is reached";
  return "the file size limit (ulimit -f) is reached";
}

std::string errno_text(int err) {
  // The message a user can act on: strerror's "No space left on device" names no remedy.
  if (err == ENOSPC || err == EDQUOT) return "the disk is full";
  if (err == EFBIG) return file_size_limit_text();
  return std::generic_category().message(err);
}

/// When this process started (static initialisation), for remove_stale_temporaries.
const fs::file_time_type g_process_start = fs::file_time_type::clock::now();

// --- registry of temporary paths, read by the signal handler -----------------------------------
// A fixed table of slots, so the handler needs no allocation or lock: a slot is claimed with a
// compare-exchange (free -> filling), filled, then published (ready); the handler touches only
// ready slots and calls only unlink and rmdir, which are async-signal-safe.
constexpr int kSlots = 64;
constexpr std::size_t kMaxPath = 4096;
enum SlotState : int { kFree = 0, kFilling = 1, kReady = 2 };
struct Slot {
  std::atomic<int> state{kFree};
  bool directory = false;
  char path[kMaxPath] = {};
};
Slot g_slots[kSlots];
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs lock-free atomics");

int register_path(const fs::path& path, bool directory) {
  std::error_code ec;
  const std::string absolute = fs::absolute(path, ec).string();  // the handler must not depend on a later chdir
  if (ec || absolute.size() >= kMaxPath) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = kFree;
    if (!g_slots[i].state.compare_exchange_strong(expected, kFilling)) continue;
    std::memcpy(g_slots[i].path, absolute.c_str(), absolute.size() + 1);
    g_slots[i].directory = directory;
    g_slots[i].state.store(kReady, std::memory_order_release);
    return i;
  }
  return -1;
}

extern "C" void remove_temporaries_and_reraise(int sig) {
  const int saved_errno = errno;
  for (int pass = 0; pass < 2; ++pass)  // files first, then the (now empty) folders
    for (Slot& s : g_slots) {
      if (s.state.load(std::memory_order_acquire) != kReady || s.directory != (pass == 1)) continue;
      if (s.directory) ::rmdir(s.path);
      else ::unlink(s.path);
    }
  errno = saved_errno;
  // The handler was installed with SA_RESETHAND, so the default action is back: end as the signal says.
  ::raise(sig);
}

/// 64 random bits as 16 hex digits: from the kernel (getrandom), else std::random_device.
std::string random_hex() {
  std::uint64_t bits = 0;
  if (::getrandom(&bits, sizeof bits, 0) != static_cast<ssize_t>(sizeof bits)) {
    std::random_device device;
    bits = (static_cast<std::uint64_t>(device()) << 32) ^ device();
  }
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(bits));
  return text;
}

// The pid names the process that made the file (remove_stale_temporaries reads it back); the
// random part makes the name unguessable, so nobody can plant a file or a symbolic link under it
// beforehand, and unique across processes and calls.
fs::path temp_path_for(const fs::path& target) {
  // Built by appending: GCC 12 warns falsely (-Wrestrict) about "literal" + std::string here.
  std::string name = ".";
  name += target.stem().string();
  name += ".tmp-" + std::to_string(::getpid()) + "-" + random_hex();
  name += target.extension().string();
  return target.parent_path() / name;
}

/// The pid in `name` when it is a temporary name of temp_path_for(destination), else -1.
long temporary_pid(const std::string& name, const fs::path& destination) {
  std::string prefix = ".";
  prefix += destination.stem().string();
  prefix += ".tmp-";
  const std::string ext = destination.extension().string();
  if (!name.starts_with(prefix) || !name.ends_with(ext) || name.size() <= prefix.size() + ext.size()) return -1;
  const std::string middle = name.substr(prefix.size(), name.size() - prefix.size() - ext.size());  // "<pid>-<hex>"
  const std::size_t dash = middle.find('-');
  if (dash == 0 || dash == std::string::npos || dash + 1 == middle.size()) return -1;
  if (middle.substr(0, dash).find_first_not_of("0123456789") != std::string::npos ||
      middle.substr(dash + 1).find_first_not_of("0123456789abcdef") != std::string::npos)
    return -1;
  try {
    return std::stol(middle.substr(0, dash));
  } catch (const std::exception&) {
    return -1;
  }
}

/// Why writing `temp` in `dir` failed, when the cause is the disk or the file size limit (the
/// writers' libraries say "Write Error" or "write failed"); empty when it is neither.
std::string storage_failure(const fs::path& temp, const fs::path& dir) {
  struct statvfs vfs {};
  // Full when what an unprivileged writer may still use would not hold one more block.
  if (::statvfs(dir.c_str(), &vfs) == 0 && vfs.f_bavail == 0) return "the disk is full";
  struct rlimit limit {};
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(temp, ec);
  if (!ec && ::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY && size >= limit.rlim_cur)
    return file_size_limit_text();
  return {};
}

const char* file_type_name(fs::file_type t) {
  switch (t) {
    case fs::file_type::fifo: return "a FIFO (named pipe)";
    case fs::file_type::character: return "a character device";
    case fs::file_type::block: return "a block device";
    case fs::file_type::socket: return "a socket";
    case fs::file_type::directory: return "a directory";
    default: return "not a regular file";
  }
}

// Flushes the file's data to disk before the rename, so that after a crash the destination holds
// either the old file or the complete new one, never a renamed but empty file.
void sync_file(const fs::path& file, const fs::path& reported) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) throw SystemError(reported.string() + ": cannot reopen the temporary file: " + errno_text(errno));
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0) throw SystemError(reported.string() + ": cannot flush to disk: " + errno_text(err));
}

thread_local detail::DeferredRenames* t_deferred = nullptr;

}  // namespace

TemporaryRegistration::TemporaryRegistration(const fs::path& path, bool directory) : slot_(register_path(path, directory)) {}

TemporaryRegistration::~TemporaryRegistration() {
  if (slot_ >= 0) g_slots[slot_].state.store(kFree, std::memory_order_release);
}

TemporaryRegistration::TemporaryRegistration(TemporaryRegistration&& other) noexcept : slot_(other.slot_) { other.slot_ = -1; }

TemporaryRegistration& TemporaryRegistration::operator=(TemporaryRegistration&& other) noexcept {
  if (this != &other) {
    if (slot_ >= 0) g_slots[slot_].state.store(kFree, std::memory_order_release);
    slot_ = other.slot_;
    other.slot_ = -1;
  }
  return *this;
}

void ignore_file_size_signal() {
  struct sigaction action {};
  action.sa_handler = SIG_IGN;
  sigemptyset(&action.sa_mask);
  ::sigaction(SIGXFSZ, &action, nullptr);
}

int open_temporary_descriptor(const fs::path& temp, const fs::path& reported) {
  // No O_CREAT: the file write_file_atomically created exclusively must still be there, and a
  // symbolic link put in its place is not followed.
  const int fd = ::open(temp.c_str(), O_WRONLY | O_TRUNC | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) throw SystemError(reported.string() + ": cannot open the temporary file for writing: " + errno_text(errno));
  return fd;
}

std::FILE* open_temporary(const fs::path& temp, const fs::path& reported) {
  const int fd = open_temporary_descriptor(temp, reported);
  std::FILE* f = ::fdopen(fd, "wb");
  if (f == nullptr) {
    const int err = errno;
    ::close(fd);
    throw SystemError(reported.string() + ": cannot open the temporary file for writing: " + errno_text(err));
  }
  return f;
}

void close_temporary(std::FILE* file, const fs::path& reported) {
  const bool flushed = std::fflush(file) == 0 && std::ferror(file) == 0;
  const int err = errno;
  if (std::fclose(file) != 0 || !flushed) throw SystemError(reported.string() + ": cannot write: " + errno_text(flushed ? errno : err));
}

void write_bytes_atomically(const fs::path& path, std::string_view bytes) {
  write_file_atomically(path, [&](const fs::path& temp) {
    std::FILE* f = open_temporary(temp, path);
    const bool written = bytes.empty() || std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
    const int err = errno;
    if (!written) {
      std::fclose(f);
      throw SystemError(path.string() + ": cannot write: " + errno_text(err));
    }
    close_temporary(f, path);
  });
}

void remove_temporaries_on_signals() {
  struct sigaction action {};
  action.sa_handler = remove_temporaries_and_reraise;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction old {};
    // A signal the parent chose to ignore (e.g. nohup's SIGHUP) stays ignored.
    if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    ::sigaction(sig, &action, nullptr);
  }
}

namespace detail {

fs::path temporary_path_for(const fs::path& destination) { return temp_path_for(destination); }

std::string random_suffix() { return random_hex(); }

DeferredRenames::DeferredRenames(Keep keep) : keep_(std::move(keep)), outer_(t_deferred) { t_deferred = this; }
DeferredRenames::~DeferredRenames() { t_deferred = outer_; }
DeferredRenames* DeferredRenames::current() { return t_deferred; }
void DeferredRenames::keep(const fs::path& temp, const fs::path& destination, TemporaryRegistration registration) const {
  keep_(temp, destination, std::move(registration));
}

}  // namespace detail

void check_output_destination(const fs::path& path, const std::string& what) {
  // A line break in a name would break every one-line message and summary that names the file.
  const std::string name = path.string();
  if (std::any_of(name.begin(), name.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; })) {
    std::string shown;
    for (char c : name.substr(0, 80)) shown += static_cast<unsigned char>(c) < 0x20 || c == 0x7f ? '?' : c;
    throw InputError("'" + shown + "': " + what + " has a line break or another control character in its name; ao writes no such names");
  }
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);  // follows symbolic links
  if (ec || !fs::exists(st) || fs::is_regular_file(st)) return;
  const std::string type = file_type_name(st.type());
  const std::string through = fs::is_symlink(fs::symlink_status(path, ec)) ? "a symbolic link to " : "";
  if (fs::is_directory(st)) throw InputError(path.string() + ": " + what + " is " + through + "a directory, not a file");
  throw InputError(path.string() + ": " + what + " is " + through + type + ", not a regular file; ao writes only regular files or new paths");
}

namespace {

// Removes the temporary files of other processes beside `destination` (write_file_atomically's
// names) that `abandoned` accepts, after rolling back the interrupted commits in its folder: those
// of processes gone, or, when the caller `owned` the destination, those that list it.
int remove_temporaries_of(const fs::path& destination, const std::function<bool(long pid, const fs::directory_entry&)>& abandoned, bool owned) {
  std::error_code ec;
  fs::path target = destination;
  if (fs::is_symlink(destination, ec)) {
    const fs::path resolved = fs::weakly_canonical(destination, ec);
    if (!ec) target = resolved;
  }
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  // A killed run's commit first: its journal names the staged files and links it needs to roll
  // back, which the loop below would otherwise remove as stale.
  detail::recover_interrupted_commits(dir, owned ? target : fs::path());
  int removed = 0;
  fs::directory_iterator it(dir, ec);
  for (; !ec && it != fs::directory_iterator(); it.increment(ec)) {
    const fs::path& p = it->path();
    const long pid = temporary_pid(p.filename().string(), target);
    if (pid <= 0 || pid == ::getpid()) continue;
    std::error_code file_ec;
    if (!it->is_regular_file(file_ec) || file_ec || !abandoned(pid, *it)) continue;
    if (fs::remove(p, file_ec)) ++removed;
  }
  return removed;
}

}  // namespace

int remove_stale_temporaries(const fs::path& destination) {
  return remove_temporaries_of(destination, [](long pid, const fs::directory_entry& file) {
    // A process that still runs (or that we may not signal, EPERM) is not ours to clean up after.
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) return false;
    std::error_code ec;
    return file.last_write_time(ec) < g_process_start && !ec;
  }, false);
}

int remove_abandoned_temporaries(const fs::path& destination) {
  return remove_temporaries_of(destination, [](long, const fs::directory_entry&) { return true; }, true);
}

void write_file_atomically(const fs::path& path, const std::function<void(const fs::path& temp)>& write) {
  if (path.empty() || !path.has_filename()) throw InputError("'" + path.string() + "': output path names no file");
  check_output_destination(path);

  // Replace the file a symbolic link points to rather than the link itself.
  std::error_code ec;
  fs::path target = path;
  if (fs::is_symlink(path, ec)) {
    const fs::path resolved = fs::weakly_canonical(path, ec);
    if (!ec) target = resolved;
  }
  if (fs::is_directory(target, ec)) throw InputError(path.string() + ": is a directory, not a file");

  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::exists(dir, ec)) throw InputError(path.string() + ": directory '" + dir.string() + "' does not exist");
  if (!fs::is_directory(dir, ec)) throw InputError(path.string() + ": '" + dir.string() + "' is not a directory");
  remove_stale_temporaries(target);

  // Create the temporary file here (exclusively, so it cannot clobber anything) to report an
  // unwritable directory with the destination's name rather than a library's message about a
  // temporary name the user never chose. It is registered before it exists, so a signal at any
  // point after the open finds it.
  const fs::path temp = temp_path_for(target);
  TemporaryRegistration registration(temp);
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (fd < 0) {
    const int err = errno;
    throw SystemError(path.string() + ": cannot create a file in '" + dir.string() + "': " + errno_text(err));
  }
  ::close(fd);

  try {
    write(temp);
    sync_file(temp, path);
    if (const detail::DeferredRenames* deferred = detail::DeferredRenames::current()) {
      deferred->keep(temp, target, std::move(registration));
      return;
    }
    fs::rename(temp, target, ec);
    if (ec) throw SystemError(path.string() + ": cannot rename the temporary file into place: " + errno_text(ec.value()));
  } catch (const SystemError&) {
    const std::string cause = storage_failure(temp, dir);
    fs::remove(temp, ec);  // best effort: the original error is the one worth reporting
    if (!cause.empty()) throw SystemError(path.string() + ": cannot write: " + cause);
    throw;
  } catch (...) {
    fs::remove(temp, ec);
    throw;
  }
}

}  // namespace ao
