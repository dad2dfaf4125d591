// SPDX-License-Identifier: Apache-2.0
// ao: ambient occlusion on the CPU. The only place errors become exit codes:
//   0 success, 1 bad input (file, option value, including a value of the wrong type), 2 bad usage
//   (unknown option, missing argument), 3 system failure (disk, library, not enough memory),
//   4 internal error.
#include <cstdio>
#include <exception>
#include <functional>
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
