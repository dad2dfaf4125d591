// SPDX-License-Identifier: Apache-2.0
// The outputs of one run as one transaction (SPEC, "Behaviour on bad input"): every output is
// declared before the work starts, so one that names an input or another output is refused while
// nothing has been computed or written; each is then written to a temporary file beside its
// destination (write_file_atomically, deferred), and all are renamed into place only when every
// one was written. A run that fails, or an OutputSet destroyed without commit(), removes its
// temporary files and leaves every existing file as it was.
//
//   OutputSet outputs;
//   outputs.add_input(mesh_path, "the mesh");
//   outputs.add_output(map_path, "-o");           // InputError here if it names the mesh
//   ... work ...
//   outputs.write(map_path, [&] { write_image(map_path, map); });
//   outputs.commit();
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "ao/io/atomic_file.h"

namespace ao {

class OutputSet {
 public:
  OutputSet() = default;
  /// Without commit(): removes the temporary files and the folders add_directory created.
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  /// Declares a file the run reads, named by `what` in messages ("--gbuffer-in", "the mesh").
  /// An output naming it is refused. A path that does not exist is ignored (its loader reports it).
  void add_input(const std::filesystem::path& path, std::string what);

  /// Declares an output file, named by `what` in messages ("-o", "--shaded"). InputError, one line
  /// naming the path, when it names a declared input or output (the same path after resolving
  /// ".", ".." and symbolic links, or the same file through a hard link), when it is a directory,
  /// a FIFO, a device node or a socket, or a symbolic link to one (check_output_destination),
  /// or when its folder does not exist (and is not one add_directory will create). Declaring the
  /// same output twice with the same `what` is a no-op. Removes the temporary files that killed
  /// runs left for it (remove_stale_temporaries).
  void add_output(const std::filesystem::path& path, std::string what);

  /// Declares an output folder: used as it is when it exists (InputError when it is not a
  /// directory), otherwise created by the first write into it (its parent must exist) and removed
  /// again if the run fails.
  void add_directory(const std::filesystem::path& dir, std::string what);

  /// Runs `write`, which writes `path` with the library's writers (write_image, write_gbuffer_exr,
  /// ...; anything built on write_file_atomically): their temporary files are kept for commit()
  /// instead of being renamed. `path` is declared first if it was not (add_output, same checks).
  /// Exceptions of `write` propagate; what it had written is removed at the latest by the destructor.
  void write(const std::filesystem::path& path, const std::function<void()>& write, std::string what = "output");

  /// The file holding what write() staged for `path`, to read an output back before commit();
  /// InputError if nothing was written for it.
  std::filesystem::path staged(const std::filesystem::path& path) const;

  /// Renames every staged file over its destination, in the order they were written, as one
  /// transaction: each destination that holds a file keeps it under a hidden name (a hard link,
  /// or a copy) until all renames succeeded. When a rename fails (a broken or full file system, a
  /// destination turned into a directory meanwhile), the destinations already replaced get their
  /// previous files back, the new ones are removed, and a SystemError names the file that failed:
  /// every output is then as it was before the run. With two outputs or more, a journal listing
  /// them is on disk before the first rename (commit_journal.h): a run killed by SIGKILL or a power
  /// cut between two renames is rolled back by the next run that writes into one of their folders
  /// (remove_stale_temporaries), so no folder keeps new and old outputs mixed. SIGINT, SIGTERM and
  /// SIGHUP are held back while the outputs are renamed and take effect after.
  void commit();

  /// Paths of the declared outputs, in declaration order.
  std::vector<std::filesystem::path> outputs() const;
  /// Destinations write() has staged so far, in write order (each once).
  std::vector<std::filesystem::path> written() const;

 private:
  struct Named {
    std::filesystem::path path;      ///< As given.
    std::filesystem::path resolved;  ///< fs::weakly_canonical of the absolute path.
    std::string what;
  };
  struct Staged {
    std::filesystem::path temp, destination;
    TemporaryRegistration registration;
  };
  struct Directory {
    std::filesystem::path path;
    bool create = false;   ///< Missing when declared: created by the first write into it.
    bool created = false;  ///< Created by this set (removed by the destructor unless committed).
    TemporaryRegistration registration;
  };
  Named name(const std::filesystem::path& path, std::string what) const;
  const Directory* directory_for(const std::filesystem::path& resolved_parent) const;

  std::vector<Named> inputs_, outputs_;
  std::vector<Staged> staged_;
  std::vector<Directory> directories_;
  bool committed_ = false;
};

namespace detail {

/// Test hook: in the next OutputSet::commit of the process, the rename of the staged file number
/// `index` (0-based, in write order) fails with errno `error` as a broken file system would; -1
/// disarms it. Tests only: a rename within one folder rarely fails, and root (which the tests may
/// run as) ignores the read-only folders that would make it fail.
void fail_commit_rename_for_testing(int index, int error);
/// The errno injected for the rename number `index`, once (then disarmed); 0 when none.
int commit_rename_fault(std::size_t index);

}  // namespace detail

}  // namespace ao
