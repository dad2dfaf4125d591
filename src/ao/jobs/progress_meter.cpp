// SPDX-License-Identifier: Apache-2.0
#include "ao/jobs/progress_meter.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <utility>

namespace ao {

double remaining_seconds(double elapsed, std::size_t done, std::size_t total) {
  if (done == 0 || done >= total) return 0.0;
  return elapsed * static_cast<double>(total - done) / static_cast<double>(done);
}

double log_progress_interval() {
  const char* text = std::getenv("AO_PROGRESS_SECONDS");
  if (text == nullptr) return 5.0;
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  // 0.05 s: more often than that a log is mostly progress; a day: a stage longer than that still
  // says something.
  return end != text && *end == '\0' && v >= 0.05 && v <= 86400.0 ? v : 5.0;
}

ProgressMeter::ProgressMeter(std::string label, Style style, std::function<void(const std::string&)> write, double interval,
                             std::function<double()> clock)
    : label_(std::move(label)), style_(style), write_(std::move(write)), interval_(interval), clock_(std::move(clock)) {
  start_ = now();
}

double ProgressMeter::now() const {
  if (clock_) return clock_();
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void ProgressMeter::update(std::size_t done, std::size_t total) {
  const double t = now() - start_;
  // A bar waits a second so that quick stages do not flash; a log waits a whole interval.
  const double first = style_ == Style::Bar ? 1.0 : interval_;
  const double every = style_ == Style::Bar ? 0.1 : interval_;
  if (t < first) return;
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || closed_ || (last_ >= 0 && t - last_ < every)) return;
  last_ = t;
  const double f = total > 0 ? static_cast<double>(done) / static_cast<double>(total) : 1.0;
  const double left = remaining_seconds(t, done, total);
  char line[160];
  if (style_ == Style::Bar) {
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(f * kWidth);
    std::snprintf(line, sizeof line, "] %3d%%  %.1fs, ~%.0fs left\033[K", static_cast<int>(f * 100), t, left);
    write_("\r" + label_ + " [" + std::string(filled, '#') + std::string(kWidth - filled, '.') + line);
    drawn_ = true;
  } else {
    std::snprintf(line, sizeof line, ": %d%% of %zu units, %.1f s elapsed, ~%.0f s left\n", static_cast<int>(f * 100), total, t, left);
    write_(label_ + line);
  }
}

void ProgressMeter::close() {
  std::lock_guard lock(mutex_);
  if (drawn_ && !closed_) write_("\r\033[K");
  closed_ = true;
}

}  // namespace ao
