// SPDX-License-Identifier: Apache-2.0
// Atomic output: a file is written under a temporary name in its own directory and renamed over
// the destination only once it is complete, so a failure (bad data, full disk, a crash) never
// leaves a half-written file and never damages a file that was already there (SPEC, "Behaviour on
// bad input"). Temporary files are registered so that a program that installs
// remove_temporaries_on_signals() removes them when it is interrupted (SIGINT, SIGTERM, SIGHUP).
// Runs with several outputs group their writes with OutputSet (output_set.h).
#pragma once

#include <cstdio>
#include <filesystem>
#include <functional>
#include <string_view>

namespace ao {

/// Writes `path` atomically. `write` receives the path of a temporary file in the same directory
/// (named `.<stem>.tmp-<pid>-<16 random hex digits><extension>`: hidden, unguessable, unique per
/// process and call, and keeping the real extension last for libraries that choose a format by
/// extension). The temporary file already exists, empty: it is created with O_EXCL and
/// O_NOFOLLOW, so neither a file nor a symbolic link planted beforehand is written through. `write`
/// must fill it, opening it with open_temporary (which follows no symbolic link either), and close
/// it before returning. Nothing is ever written to a shared temporary folder ($TMPDIR). Then the
/// temporary file is flushed to disk and renamed over `path`, which is replaced in one step
/// (a symbolic link at `path` is followed, so the file it names is replaced and the link kept).
/// Inside OutputSet::write the rename is left to OutputSet::commit.
///
/// Before the temporary file is made, check_output_destination refuses a destination that is not
/// a regular file, and remove_stale_temporaries clears what killed runs left for `path`.
/// If `write` throws, the temporary file is removed and the exception propagates unchanged.
/// Errors of its own are one line naming `path`: InputError when the destination cannot be used
/// (its directory does not exist, it is a directory, a FIFO, a device or a socket), SystemError
/// when the environment fails (no permission to create the temporary file, cannot flush or
/// rename; a full disk says "cannot write: the disk is full", a file size limit "cannot write: the
/// file size limit (ulimit -f) of N bytes is reached").
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(const std::filesystem::path& temp)>& write);

/// write_file_atomically with `bytes` as the file's whole content.
void write_bytes_atomically(const std::filesystem::path& path, std::string_view bytes);

/// Opens `temp`, a temporary file write_file_atomically made, for writing from its start: with
/// O_NOFOLLOW and without O_CREAT, so the file it created is the one written, never a symbolic
/// link or a new file put in its place. SystemError naming `reported` (the destination) when it
/// cannot be opened. Close it with close_temporary.
std::FILE* open_temporary(const std::filesystem::path& temp, const std::filesystem::path& reported);

/// open_temporary as a file descriptor (for libraries that take one); the caller closes it.
int open_temporary_descriptor(const std::filesystem::path& temp, const std::filesystem::path& reported);

/// Flushes and closes a file of open_temporary; SystemError naming `reported` when a write failed
/// ("cannot write: the disk is full", "... the file size limit ... is reached").
void close_temporary(std::FILE* file, const std::filesystem::path& reported);

/// InputError "<path>: <what> is a FIFO (named pipe), not a regular file; ao writes only regular
/// files or new paths" (likewise a character or block device, a socket, a directory) when `path`
/// exists, following symbolic links, and is not a regular file: replacing it by a regular file
/// would break a pipe another program reads, or, through a symbolic link, a device node. A new
/// path, a regular file and a symbolic link to either pass. `what` names the option ("-o").
/// Also InputError for a name with a line break or another control character, which would break
/// every one-line message and summary naming the file.
void check_output_destination(const std::filesystem::path& path, const std::string& what = "the output");

/// Removes the temporary files that runs of ao killed before they could clean up (SIGKILL, a
/// power cut) left beside `destination`: hidden files named as write_file_atomically names them
/// for that destination, whose process is no longer running on this machine and which were last
/// written before this process started. Returns how many it removed. Files it cannot remove are
/// left alone; it never throws. The process test sees this machine only: in a folder shared by
/// several machines, a run elsewhere that staged the same destination before this one started and
/// has not committed yet loses its temporary file (its commit then fails cleanly); two runs writing
/// one destination at once race anyway.
int remove_stale_temporaries(const std::filesystem::path& destination);

/// Removes every temporary file that another process made for `destination` (named as
/// write_file_atomically names them), whichever machine it ran on and whenever it wrote: for a
/// caller that owns `destination` and knows no other writer of it is live, such as a task of a
/// batch that the scheduler gives to one worker at a time, rerun after the worker that held it was
/// killed (SIGKILL leaves its temporary files; remove_stale_temporaries keeps those written after
/// this process started). A commit of another process journaled in the folder is rolled back
/// when it lists `destination` (the outputs it had renamed get their previous files back); the
/// commits of other outputs there are left alone, since their writers may be running (a batch's
/// tasks share one output folder). Returns how many temporary files it removed; never throws.
int remove_abandoned_temporaries(const std::filesystem::path& destination);

/// Ignores SIGXFSZ, so that a write beyond the file size limit (ulimit -f, RLIMIT_FSIZE) fails with
/// EFBIG, which the writers report as "cannot write: the file size limit ... is reached" and clean
/// up after, instead of the signal's default action killing the process with no message and its
/// temporary files left. For programs (the CLI calls it first thing; Python ignores SIGXFSZ
/// itself); the library never changes a signal's disposition by itself. Idempotent.
void ignore_file_size_signal();

/// Installs handlers of SIGINT, SIGTERM and SIGHUP that remove every registered temporary file
/// (those of write_file_atomically and OutputSet not yet renamed or removed) and the
/// empty folders an OutputSet created, then end the process by the same signal with its default
/// action, so the parent sees the signal as usual. For programs (the CLI calls it first thing);
/// the library never installs a handler by itself. Idempotent.
void remove_temporaries_on_signals();

/// A temporary path registered for removal by the handlers of remove_temporaries_on_signals while
/// this object lives. It does not create or remove anything itself; the owner does. At most 64
/// paths of up to 4095 bytes are registered at once; one that does not fit is simply not
/// registered (it is still removed on the normal error paths, only not on a signal).
class TemporaryRegistration {
 public:
  TemporaryRegistration() = default;
  /// `directory`: removed with rmdir (only when empty), after the files.
  explicit TemporaryRegistration(const std::filesystem::path& path, bool directory = false);
  ~TemporaryRegistration();
  TemporaryRegistration(TemporaryRegistration&& other) noexcept;
  TemporaryRegistration& operator=(TemporaryRegistration&& other) noexcept;
  TemporaryRegistration(const TemporaryRegistration&) = delete;
  TemporaryRegistration& operator=(const TemporaryRegistration&) = delete;

 private:
  int slot_ = -1;
};

namespace detail {

/// A fresh temporary name for `destination` as write_file_atomically makes them (hidden, in the
/// same folder, unique per process and call); nothing is created.
std::filesystem::path temporary_path_for(const std::filesystem::path& destination);

/// 64 random bits as 16 hex digits (getrandom): the unguessable part of temporary names.
std::string random_suffix();

/// While alive, write_file_atomically on this thread does not rename its complete temporary file:
/// it calls `keep(temp, destination, registration)` and leaves the file to the callee (OutputSet).
class DeferredRenames {
 public:
  using Keep = std::function<void(const std::filesystem::path& temp, const std::filesystem::path& destination, TemporaryRegistration registration)>;
  explicit DeferredRenames(Keep keep);
  ~DeferredRenames();
  DeferredRenames(const DeferredRenames&) = delete;
  DeferredRenames& operator=(const DeferredRenames&) = delete;
  /// The innermost live scope of this thread, or null.
  static DeferredRenames* current();
  void keep(const std::filesystem::path& temp, const std::filesystem::path& destination, TemporaryRegistration registration) const;

 private:
  Keep keep_;
  DeferredRenames* outer_;
};

}  // namespace detail

}  // namespace ao
