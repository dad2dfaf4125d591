// SPDX-License-Identifier: Apache-2.0
// How a job talks to its caller while it runs: stages with progress, warnings, and lines for
// people. The command line prints them to stderr, the viewer shows them, the Python module turns
// warnings into Python warnings; a caller that wants none leaves the members empty. Lines may mark
// request fields (field(), core/error.h): name_fields() names them in the caller's own words.
#pragma once

#include <functional>
#include <string>

#include "ao/core/progress.h"

namespace ao {

struct JobReporter {
  /// Called when a stage starts ("G-buffer", "raytraced", "bake cube.obj"); the stage's progress
  /// goes to the returned function (which may be empty). A stage ends when the next one starts or
  /// the job returns. A progress function may throw to stop the job (the exception propagates).
  std::function<ProgressFn(const std::string& stage)> stage;
  /// A problem the job worked around (a degenerate triangle dropped, an open mesh): one line,
  /// without a "warning: " prefix.
  std::function<void(const std::string& line)> warning;
  /// A line for people about what was done ("wrote ao.png: ..."): what `ao` prints without --json.
  std::function<void(const std::string& line)> note;
  /// The one-line error of one item of a batch that goes on without it (a mesh that failed).
  std::function<void(const std::string& line)> error;
  /// A line about a batch's progress meant for logs ("mesh 2 of 5: cow.obj ... done in 1.2 s"); a
  /// terminal shows the stages' progress instead.
  std::function<void(const std::string& line)> log;

  /// stage(name), or an empty ProgressFn.
  ProgressFn start(const std::string& name) const { return stage ? stage(name) : ProgressFn{}; }
  void warn(const std::string& line) const {
    if (warning) warning(line);
  }
  void tell(const std::string& line) const {
    if (note) note(line);
  }
  void fail(const std::string& line) const {
    if (error) error(line);
  }
  void trace(const std::string& line) const {
    if (log) log(line);
  }
};

}  // namespace ao
