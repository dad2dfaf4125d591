// One job at a time on a thread of its own. `ao view`'s frame loop starts the next image's G-buffer
// and method here and draws the previous image on the main thread meanwhile (one frame of
// pipelining): on a CPU the drawing (llvmpipe, the X server's copy of the frame) leaves cores idle
// that the compute can use.
#pragma once

#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace ao::view {

class BackgroundTask {
 public:
  BackgroundTask();
  /// Waits for the job in flight, if any (what it threw is dropped), then ends the thread.
  ~BackgroundTask();
  BackgroundTask(const BackgroundTask&) = delete;
  BackgroundTask& operator=(const BackgroundTask&) = delete;

  /// Runs `job` on the thread and returns at once. Precondition: not busy() (wait() first).
  void start(std::function<void()> job);
  /// Blocks until the job started last has ended, then rethrows what it threw. Everything the job
  /// wrote is visible to the caller after the return. Returns at once when nothing was started.
  void wait();
  /// A job was started and not yet waited for (it may have ended already).
  bool busy() const { return busy_; }

 private:
  void run();

  std::mutex mutex_;
  std::condition_variable wake_;
  std::function<void()> job_;  ///< The job to run; empty once the thread has taken it.
  bool running_ = false;       ///< The thread has taken the job and not yet finished it.
  bool quit_ = false;
  std::exception_ptr error_;
  bool busy_ = false;          ///< Touched by the caller's thread only.
  std::thread thread_;
};

}  // namespace ao::view
