// SPDX-License-Identifier: Apache-2.0
// Progress reporting from parallel kernels to whoever shows it (the CLI's bar on stderr).
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>

namespace ao {

/// Called with (units done, units in all) as work completes, possibly from several threads at
/// once: implementations must be thread-safe and cheap. May be empty.
using ProgressFn = std::function<void(std::size_t done, std::size_t total)>;

/// Counts completed units across threads and forwards the running total to a ProgressFn.
class ProgressCounter {
 public:
  ProgressCounter(const ProgressFn& fn, std::size_t total) : fn_(fn), total_(total) {}
  void add(std::size_t units) {
    const std::size_t done = done_.fetch_add(units, std::memory_order_relaxed) + units;
    if (fn_) fn_(done, total_);
  }

 private:
  const ProgressFn& fn_;
  std::size_t total_;
  std::atomic<std::size_t> done_{0};
};

}  // namespace ao
