// SPDX-License-Identifier: Apache-2.0
// The viewer's ground truth: the ray-traced reference of the method being looked at (its own
// membership and R, from the registry), accumulated batch after batch on a background thread
// while the camera is still, so the error of the method against it can be shown live.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "ao/core/gbuffer.h"
#include "ao/core/image.h"
#include "ao/core/membership.h"
#include "ao/reference/ray_scene.h"
#include "ao/reference/reference.h"

namespace ao::view {

/// What the reference computes: the method's matched reference (MethodInfo::reference) over this
/// G-buffer.
struct ReferenceJob {
  std::shared_ptr<const GBuffer> gbuffer;
  const RayScene* scene = nullptr;
  ReferenceSpec spec;
  std::uint32_t seed = 1;
};

/// The running estimate: V per pixel is the mean of the batch estimates so far; its standard error
/// comes from their spread (batches use independent sample sets), so it needs two batches.
struct ReferenceSnapshot {
  Image<float> visibility;      ///< Mean over batches; empty before the first batch.
  int samples_per_pixel = 0;    ///< Rays per covered pixel so far.
  int batches = 0;
  std::optional<double> mean_std_error;  ///< Over covered pixels; empty until two batches allow an estimate.
  std::uint64_t version = 0;    ///< Grows with every completed batch and every restart.
};

class ProgressiveReference {
 public:
  /// `batch_samples` rays per pixel per batch (>= 1); `max_samples` stops accumulating (>= batch).
  ProgressiveReference(int batch_samples, int max_samples);
  ~ProgressiveReference();
  ProgressiveReference(const ProgressiveReference&) = delete;
  ProgressiveReference& operator=(const ProgressiveReference&) = delete;

  /// Drops everything accumulated and starts over on `job`. A batch in flight is discarded.
  void restart(ReferenceJob job);
  /// Stops accumulating (the camera is moving); the next restart() resumes.
  void stop();
  /// Version of the newest estimate; poll it to know when to copy a snapshot.
  std::uint64_t version() const { return version_.load(std::memory_order_acquire); }
  /// A copy of the newest estimate.
  ReferenceSnapshot snapshot() const;
  /// The error of the last batch, if it threw (e.g. a parameter the reference refuses); empty otherwise.
  std::string error() const;

 private:
  void run();

  const int batch_samples_, max_samples_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  ReferenceJob job_;
  bool has_job_ = false;
  bool quit_ = false;
  std::uint64_t generation_ = 0;  ///< Bumped by restart/stop; a batch of an older generation is thrown away.
  Image<double> sum_, sum_sq_;    ///< Per pixel: sum of batch means and of their squares.
  ReferenceSnapshot snapshot_;
  std::string error_;
  std::atomic<std::uint64_t> version_{0};
  std::thread worker_;
};

}  // namespace ao::view
