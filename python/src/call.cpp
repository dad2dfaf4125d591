// SPDX-License-Identifier: Apache-2.0
#include "call.h"

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "ao/core/error.h"
#include "field_names.h"

namespace ao::python {

namespace {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

struct Call::State {
  std::thread::id python_thread = std::this_thread::get_id();
  std::atomic<bool> interrupted{false};
  std::atomic<std::int64_t> last_check_ns{0};
  std::mutex mutex;
  std::vector<std::string> warnings;
  PyObject* type = nullptr;  ///< The exception the signal handler or the progress function raised (owned references).
  PyObject* value = nullptr;
  PyObject* traceback = nullptr;
  // The caller's progress function and what it was last told; the stage and the counts are
  // written by any thread, read by the calling thread.
  py::object progress;
  std::string stage;  ///< Guarded by `mutex`.
  std::atomic<std::size_t> done{0}, total{0};
  std::int64_t last_progress_ns = 0;  ///< Calling thread only.

  // Progress arrives from every worker thread; only the calling thread may run Python's signal
  // handlers and the progress function, and it does so at most every 20 ms (a GIL round trip
  // costs microseconds, a tile of work milliseconds). Once interrupted, every thread's next
  // progress call stops its work.
  void check() {
    if (interrupted.load(std::memory_order_relaxed)) throw Interrupted{};
    if (std::this_thread::get_id() != python_thread) return;
    const std::int64_t now = now_ns();
    if (now - last_check_ns.load(std::memory_order_relaxed) < 20'000'000) return;
    last_check_ns.store(now, std::memory_order_relaxed);
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() == 0 && report(now, false)) return;
    PyErr_Fetch(&type, &value, &traceback);
    interrupted.store(true);
    throw Interrupted{};
  }

  // Calls the progress function (GIL held) every 100 ms, or now when `force`; false when it
  // raised (the Python error is then set).
  bool report(std::int64_t now, bool force) {
    if (progress.is_none() || (!force && now - last_progress_ns < 100'000'000)) return true;
    last_progress_ns = now;
    std::string name;
    {
      std::lock_guard lock(mutex);
      name = stage;
    }
    if (name.empty()) return true;
    PyObject* r = PyObject_CallFunction(progress.ptr(), "snn", name.c_str(), static_cast<Py_ssize_t>(done.load()), static_cast<Py_ssize_t>(total.load()));
    Py_XDECREF(r);
    return r != nullptr;
  }
};

Call::Call(py::object progress) : state_(std::make_shared<State>()) {
  state_->progress = std::move(progress);
  reporter_.stage = [s = state_](const std::string& stage) -> ProgressFn {
    {
      std::lock_guard lock(s->mutex);
      s->stage = stage;
    }
    s->done = 0;
    s->total = 0;
    return [s](std::size_t done, std::size_t total) {
      s->done.store(done, std::memory_order_relaxed);
      s->total.store(total, std::memory_order_relaxed);
      s->check();
    };
  };
  reporter_.warning = [s = state_](const std::string& line) {
    std::lock_guard lock(s->mutex);
    s->warnings.push_back(name_fields(line, keyword_name));
  };
}

Call::~Call() {
  Py_XDECREF(state_->type);
  Py_XDECREF(state_->value);
  Py_XDECREF(state_->traceback);
  if (!state_->progress.is_none()) {
    py::gil_scoped_acquire gil;  // held already where a Call lives; the object is released under it
    state_->progress = py::object();
  }
}

void Call::restore_interrupt() {
  if (!state_->type) PyErr_SetNone(PyExc_KeyboardInterrupt);
  else PyErr_Restore(state_->type, state_->value, state_->traceback);  // steals the references
  state_->type = state_->value = state_->traceback = nullptr;
}

void Call::finish_progress() {
  if (state_->progress.is_none()) return;
  state_->done.store(state_->total.load());
  if (!state_->report(now_ns(), true)) throw py::error_already_set();
}

void Call::issue_warnings(bool raise) {
  std::vector<std::string> lines;
  {
    std::lock_guard lock(state_->mutex);
    lines.swap(state_->warnings);
  }
  for (const std::string& line : lines)
    if (PyErr_WarnEx(PyExc_UserWarning, line.c_str(), 2) != 0) {
      if (raise) throw py::error_already_set();
      PyErr_Clear();
    }
}

}  // namespace ao::python
