// SPDX-License-Identifier: Apache-2.0
// What `ao view` measures about its frames and shows in the HUD: the wall time of each stage
// (G-buffer, method, filter, display), averaged over the last second for the HUD and over the whole
// run for --json, and the reference's state.
#pragma once

#include <chrono>
#include <deque>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/gpu/device.h"

namespace ao::view {

using Clock = std::chrono::steady_clock;

/// Milliseconds since `t`.
double ms_since(Clock::time_point t);

/// Per-stage wall times of one frame, ms; a stage that did not run this frame is 0.
struct StageTimes {
  double gbuffer = 0, method = 0, filter = 0, display = 0, frame = 0;
  double image = 0;  ///< The part of display that builds and uploads the 8-bit image (0: unchanged).
};

class StageStats {
 public:
  void add(const StageTimes& t);
  /// The time of each stage the last time it ran.
  const StageTimes& last_run() const { return last_; }
  /// Mean of each stage over the frames in which it ran during the last second; `fps` gets the
  /// frames of that second.
  StageTimes recent(double& fps) const;
  /// Means over the whole run: frames, fps, frame_ms and each stage's ms, and how often the
  /// G-buffer and the method ran.
  nlohmann::json json() const;

 private:
  std::deque<std::pair<Clock::time_point, StageTimes>> recent_;
  StageTimes total_, runs_, last_;
  long frames_ = 0;
};

/// What the panel and the HUD show about the reference and the image.
struct ViewerReadout {
  int reference_spp = 0;
  std::string std_error;  ///< "-" until two batches allow an estimate.
  double rmse = -1;       ///< Of the method against the reference; < 0 when unknown.
  std::string error;      ///< The last one-line error; empty if none.
  int width = 0, height = 0;  ///< Of the computed image.
  std::string gl_renderer;    ///< The GPU backend's renderer when the method ran on it; empty on the CPU.
  std::vector<GpuPassTime> gpu_passes;  ///< Its passes in the last run, in the order they ran.
  bool benchmark = false;     ///< --benchmark: the method is recomputed every frame.
};

/// The HUD (top right): frames per second, each stage's ms, the reference's rays per pixel and
/// standard error, and the method's RMSE against it; on the GPU the renderer and each pass's GPU ms.
void draw_hud(const StageStats& stats, const ViewerReadout& readout);

/// A message in the middle of the image, which starts `left` pixels from the window's left edge:
/// why a view that needs the reference is empty.
void draw_notice(const std::string& text, float left);

}  // namespace ao::view
