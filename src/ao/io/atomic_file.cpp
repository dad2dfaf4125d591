#include "ao/io/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <string>
#include <system_error>

#include "ao/core/error.h"

namespace ao {

namespace fs = std::filesystem;

namespace {

std::string errno_text(int err) { return std::generic_category().message(err); }

// Unique within the process (the counter) and across processes (the pid), so concurrent writers
// of the same destination never share a temporary file.
fs::path temp_path_for(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  // Built by appending: GCC 12 warns falsely (-Wrestrict) about "literal" + std::string here.
  std::string name = ".";
  name += target.stem().string();
  name += ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter.fetch_add(1));
  name += target.extension().string();
  return target.parent_path() / name;
}

// Flushes the file's data to disk before the rename, so that after a crash the destination holds
// either the old file or the complete new one, never a renamed but empty file.
void sync_file(const fs::path& file, const fs::path& reported) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw SystemError(reported.string() + ": cannot reopen the temporary file: " + errno_text(errno));
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0) throw SystemError(reported.string() + ": cannot flush to disk: " + errno_text(err));
}

}  // namespace

void write_file_atomically(const fs::path& path, const std::function<void(const fs::path& temp)>& write) {
  if (path.empty() || !path.has_filename()) throw InputError("'" + path.string() + "': output path names no file");

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

  // Create the temporary file here (exclusively, so it cannot clobber anything) to report an
  // unwritable directory with the destination's name rather than a library's message about a
  // temporary name the user never chose.
  const fs::path temp = temp_path_for(target);
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) {
    const int err = errno;
    throw SystemError(path.string() + ": cannot create a file in '" + dir.string() + "': " + errno_text(err));
  }
  ::close(fd);

  try {
    write(temp);
    sync_file(temp, path);
    fs::rename(temp, target, ec);
    if (ec) throw SystemError(path.string() + ": cannot rename the temporary file into place: " + ec.message());
  } catch (...) {
    fs::remove(temp, ec);  // best effort: the original error is the one worth reporting
    throw;
  }
}

}  // namespace ao
