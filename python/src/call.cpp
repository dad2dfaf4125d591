#include "call.h"

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace ao::python {

struct Call::State {
  std::thread::id python_thread = std::this_thread::get_id();
  std::atomic<bool> interrupted{false};
  std::atomic<std::int64_t> last_check_ns{0};
  std::mutex mutex;
  std::vector<std::string> warnings;
  PyObject* type = nullptr;  ///< The exception the signal handler raised (owned references).
  PyObject* value = nullptr;
  PyObject* traceback = nullptr;

  // Progress arrives from every worker thread; only the calling thread may run Python's signal
  // handlers, and it does so at most every 20 ms (a GIL round trip costs microseconds, a tile of
  // work milliseconds). Once interrupted, every thread's next progress call stops its work.
  void check() {
    if (interrupted.load(std::memory_order_relaxed)) throw Interrupted{};
    if (std::this_thread::get_id() != python_thread) return;
    const std::int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
    if (now - last_check_ns.load(std::memory_order_relaxed) < 20'000'000) return;
    last_check_ns.store(now, std::memory_order_relaxed);
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() == 0) return;
    PyErr_Fetch(&type, &value, &traceback);
    interrupted.store(true);
    throw Interrupted{};
  }
};

Call::Call() : state_(std::make_shared<State>()) {
  reporter_.stage = [s = state_](const std::string&) -> ProgressFn { return [s](std::size_t, std::size_t) { s->check(); }; };
  reporter_.warning = [s = state_](const std::string& line) {
    std::lock_guard lock(s->mutex);
    s->warnings.push_back(line);
  };
}

Call::~Call() {
  Py_XDECREF(state_->type);
  Py_XDECREF(state_->value);
  Py_XDECREF(state_->traceback);
}

void Call::restore_interrupt() {
  if (!state_->type) PyErr_SetNone(PyExc_KeyboardInterrupt);
  else PyErr_Restore(state_->type, state_->value, state_->traceback);  // steals the references
  state_->type = state_->value = state_->traceback = nullptr;
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
