// SPDX-License-Identifier: Apache-2.0
// A job stage's progress as text for people: on a terminal a bar redrawn in place, in a log (a
// file, CI, a render farm: stderr not a terminal) a line every few seconds. Both give the fraction
// of the work done, the time elapsed and the time left, estimated from work units (pixels, texels,
// vertices: what the stage's ProgressFn counts), not from tiles or rows, so that work that costs
// nothing (background pixels) does not make the estimate optimistic.
#pragma once

#include <cstddef>
#include <functional>
#include <mutex>
#include <string>

namespace ao {

/// Seconds left of a stage that has done `done` of `total` units in `elapsed` seconds, at the rate
/// so far: elapsed x (total - done) / done. 0 when done is 0 or total (nothing to go on, or
/// finished).
double remaining_seconds(double elapsed, std::size_t done, std::size_t total);

/// Seconds between the lines of a log: the environment variable AO_PROGRESS_SECONDS when it is a
/// number in [0.05, 86400], else 5.
double log_progress_interval();

class ProgressMeter {
 public:
  enum class Style {
    Bar,  ///< "\r<label> [####......]  40%  3.1s, ~4s left", redrawn at most ten times a second.
    Log,  ///< "<label>: 40% of 921600 units, 3.1 s elapsed, ~4 s left\n", every `interval` seconds.
  };
  /// `write` receives the text (thread-safe: called under the meter's lock); `clock` gives seconds
  /// from any origin (default: the steady clock). Nothing is written during the first second,
  /// so quick stages stay silent; a log's first line comes after `interval` seconds.
  ProgressMeter(std::string label, Style style, std::function<void(const std::string&)> write, double interval = 5.0,
                std::function<double()> clock = {});

  /// `done` of `total` units: a ProgressFn's arguments. Thread-safe and cheap; updates that arrive
  /// while another thread writes are skipped.
  void update(std::size_t done, std::size_t total);
  /// Ends the stage: a bar that was drawn is erased; a log writes nothing more.
  void close();

 private:
  double now() const;

  std::string label_;
  Style style_;
  std::function<void(const std::string&)> write_;
  double interval_;
  std::function<double()> clock_;
  double start_ = 0, last_ = -1;
  std::mutex mutex_;
  bool drawn_ = false, closed_ = false;
};

}  // namespace ao
