// The viewer's compute thread: jobs run off the caller's thread, one at a time, and what a job
// writes or throws reaches the caller through wait().
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "view/background_task.h"

namespace ao::test {
namespace {

TEST(BackgroundTask, RunsEachJobOffTheCallersThreadAndPublishesItsWrites) {
  view::BackgroundTask task;
  EXPECT_FALSE(task.busy());
  task.wait();  // nothing started: returns at once
  std::vector<int> written;
  std::thread::id ran_on;
  for (int i = 0; i < 100; ++i) {
    task.start([&, i] {
      written.push_back(i);  // plain memory: wait() must order it before the caller's reads
      ran_on = std::this_thread::get_id();
    });
    EXPECT_TRUE(task.busy());
    task.wait();
    EXPECT_FALSE(task.busy());
    ASSERT_EQ(written.size(), static_cast<std::size_t>(i + 1));
    EXPECT_EQ(written.back(), i);
    EXPECT_NE(ran_on, std::this_thread::get_id());
  }
}

TEST(BackgroundTask, WaitRethrowsWhatTheJobThrewOnce) {
  view::BackgroundTask task;
  task.start([] { throw std::runtime_error("bad parameter"); });
  EXPECT_THROW(task.wait(), std::runtime_error);
  EXPECT_NO_THROW(task.wait());  // reported once
  int value = 0;
  task.start([&] { value = 7; });  // the thread survives a job that threw
  task.wait();
  EXPECT_EQ(value, 7);
}

TEST(BackgroundTask, DestructorWaitsForTheJobInFlight) {
  std::atomic<bool> finished{false};
  {
    view::BackgroundTask task;
    task.start([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      finished = true;
    });
  }
  EXPECT_TRUE(finished);
}

}  // namespace
}  // namespace ao::test
