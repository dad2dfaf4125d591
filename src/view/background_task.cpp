#include "view/background_task.h"

#include <utility>

namespace ao::view {

BackgroundTask::BackgroundTask() { thread_ = std::thread([this] { run(); }); }

BackgroundTask::~BackgroundTask() {
  {
    std::unique_lock lock(mutex_);
    wake_.wait(lock, [&] { return !job_ && !running_; });
    quit_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void BackgroundTask::start(std::function<void()> job) {
  {
    std::lock_guard lock(mutex_);
    job_ = std::move(job);
    error_ = nullptr;
  }
  busy_ = true;
  wake_.notify_all();
}

void BackgroundTask::wait() {
  if (!busy_) return;
  std::exception_ptr error;
  {
    std::unique_lock lock(mutex_);
    wake_.wait(lock, [&] { return !job_ && !running_; });
    error = std::exchange(error_, nullptr);
  }
  busy_ = false;
  if (error) std::rethrow_exception(error);
}

void BackgroundTask::run() {
  for (;;) {
    std::function<void()> job;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return quit_ || job_; });
      if (quit_) return;
      job = std::exchange(job_, nullptr);
      running_ = true;
    }
    std::exception_ptr error;
    try {
      job();
    } catch (...) {
      error = std::current_exception();
    }
    {
      std::lock_guard lock(mutex_);
      running_ = false;
      error_ = error;
    }
    wake_.notify_all();
  }
}

}  // namespace ao::view
