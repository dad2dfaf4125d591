// SPDX-License-Identifier: Apache-2.0
// One call of a job from Python: the job runs with the GIL released; its progress callbacks check
// for Ctrl-C (the thread that called from Python runs Python's signal handlers about every 20 ms)
// and stop the job by throwing, so a KeyboardInterrupt ends a long render or bake within a
// fraction of a second; the caller's progress function, when given, is called from that thread
// too; the job's warnings become Python warnings once the GIL is held again.
#pragma once

#include <memory>
#include <utility>

#include <pybind11/pybind11.h>

#include "ao/jobs/reporter.h"

namespace ao::python {

namespace py = pybind11;

class Call {
 public:
  /// `progress`: None, or a callable(stage: str, done: int, total: int) called with the GIL held,
  /// on the calling thread, at most every 100 ms while a stage reports progress and once when
  /// the job ends. An exception it raises stops the job and propagates.
  explicit Call(py::object progress = py::none());
  ~Call();
  Call(const Call&) = delete;
  Call& operator=(const Call&) = delete;

  /// Stages report progress to a check for Ctrl-C; warnings are kept for after the call.
  const JobReporter& reporter() const { return reporter_; }

  /// `job()` with the GIL released. An interrupt is raised as the Python exception its signal
  /// handler raised (KeyboardInterrupt for Ctrl-C), or that the progress function raised; the
  /// job's warnings are issued with warnings.warn when it ends, also when it fails.
  template <class F>
  auto run(F&& job) -> decltype(job()) {
    try {
      auto result = [&] {
        py::gil_scoped_release release;
        return job();
      }();
      finish_progress();
      issue_warnings(true);
      return result;
    } catch (const Interrupted&) {
      issue_warnings(false);
      restore_interrupt();
      throw py::error_already_set();
    } catch (const py::error_already_set&) {
      throw;
    } catch (...) {
      issue_warnings(false);
      throw;
    }
  }

 private:
  struct Interrupted {};
  struct State;
  void restore_interrupt();
  /// The progress function's last call of the job: its last stage, done = total.
  void finish_progress();
  /// `raise`: a warning filter's error is raised; else (the job failed) it gives way to the job's.
  void issue_warnings(bool raise);

  std::shared_ptr<State> state_;
  JobReporter reporter_;
};

}  // namespace ao::python
