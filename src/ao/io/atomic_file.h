// Atomic output: a file is written under a temporary name in its own directory and renamed over
// the destination only once it is complete, so a failure (bad data, full disk, a crash) never
// leaves a half-written file and never damages a file that was already there (SPEC, "Behaviour on
// bad input").
#pragma once

#include <filesystem>
#include <functional>

namespace ao {

/// Writes `path` atomically. `write` receives the path of a temporary file in the same directory
/// (named `.<stem>.tmp-<pid>-<counter><extension>`: hidden, unique per process and call, and
/// keeping the real extension last for libraries that choose a format by extension). The temporary
/// file already exists, empty; `write` must fill it and close it before returning. Then the
/// temporary file is flushed to disk and renamed over `path`, which is replaced in one step
/// (a symbolic link at `path` is followed, so the file it names is replaced and the link kept).
///
/// If `write` throws, the temporary file is removed and the exception propagates unchanged.
/// Errors of its own are one line naming `path`: InputError when the destination cannot be used
/// (its directory does not exist, it is a directory), SystemError when the environment fails
/// (no permission to create the temporary file, cannot flush or rename).
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(const std::filesystem::path& temp)>& write);

}  // namespace ao
