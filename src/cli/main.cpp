// SPDX-License-Identifier: Apache-2.0
// ao: ambient occlusion on the CPU. The only place errors become exit codes:
//   0 success, 1 bad input (file, option value, including a value of the wrong type), 2 bad usage
//   (unknown option, missing argument), 3 system failure (disk, library, not enough memory),
//   4 internal error.
#include <malloc.h>

#include <cstdio>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <new>

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include "ao/core/error.h"
#include "ao/io/atomic_file.h"
#include "app.h"
#include "field_names.h"
#include "parse_errors.h"

int main(int argc, char** argv) {
  CLI::App app("ao: ambient occlusion on the CPU. Ray-traced ground truth and published AO methods.", "ao");
  ao::cli::GlobalOptions global;
  std::function<int()> action;
  ao::cli::add_ao_commands(app, global, action);

  // Interrupted runs remove their temporary files, and a file size limit is an error like a full
  // disk (atomic_file.h).
  ao::remove_temporaries_on_signals();
  ao::ignore_file_size_signal();
  // Keep freed memory in the process: blocks up to 32 MB (glibc's largest mmap threshold) come from
  // the heap, and the heap is never trimmed. Otherwise glibc returns large blocks (a bake's coverage
  // fragments, a map's scratch images, each frame's images in `ao view`) to the kernel when they are
  // freed, and the next one faults in fresh zeroed pages: a 1024^2 bake at 8 rays spent 14% of its
  // CPU in the kernel's page faults, and this cuts its whole process's CPU by 5% (docs/methods/bake.md,
  // "Speed"; BENCHMARKS.md, "ao view", for the viewer's frames). The process then keeps the most
  // memory it used at once until it exits, which a command does soon; the library leaves malloc as
  // its host set it.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, std::numeric_limits<int>::max());
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // One line in ao's words; a value of the wrong type or out of range ("--width abc", "--seed -1")
    // is a bad value (1), like the values the subcommands check; anything else bad usage (2).
    return ao::cli::report_parse_error(app, e, argc, argv);
  }
  std::unique_ptr<tbb::global_control> limit;
  if (global.threads > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(global.threads));
  try {
    return action ? action() : 0;
  } catch (const ao::InputError& e) {
    // The job layer names request fields ("BakeRequest::padding"); the command line names its options.
    std::fprintf(stderr, "ao: error: %s\n", e.message(ao::cli::option_name).c_str());
    return 1;
  } catch (const ao::SystemError& e) {
    std::fprintf(stderr, "ao: error: %s\n", e.what());
    return 3;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "ao: error: out of memory\n");
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ao: internal error: %s\n", e.what());
    return 4;
  }
}
