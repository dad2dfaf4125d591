// SPDX-License-Identifier: Apache-2.0
#include "view/progressive.h"

#include <cmath>
#include <exception>

#include "ao/core/sampling.h"

namespace ao::view {

ProgressiveReference::ProgressiveReference(int batch_samples, int max_samples)
    : batch_samples_(std::max(batch_samples, 1)), max_samples_(std::max(max_samples, batch_samples)) {
  worker_ = std::thread([this] { run(); });
}

ProgressiveReference::~ProgressiveReference() {
  {
    std::lock_guard lock(mutex_);
    quit_ = true;
    ++generation_;
  }
  wake_.notify_all();
  worker_.join();
}

void ProgressiveReference::restart(ReferenceJob job) {
  {
    std::lock_guard lock(mutex_);
    job_ = std::move(job);
    has_job_ = job_.gbuffer != nullptr && job_.scene != nullptr;
    ++generation_;
    const int w = has_job_ ? job_.gbuffer->width() : 0, h = has_job_ ? job_.gbuffer->height() : 0;
    sum_ = Image<double>(w, h, 0.0);
    sum_sq_ = Image<double>(w, h, 0.0);
    snapshot_ = ReferenceSnapshot{};
    snapshot_.version = version_.load() + 1;
    error_.clear();
    version_.store(snapshot_.version, std::memory_order_release);
  }
  wake_.notify_all();
}

void ProgressiveReference::stop() {
  std::lock_guard lock(mutex_);
  has_job_ = false;
  job_.gbuffer.reset();  // a batch in flight keeps its own copy of the pointer until it ends
  ++generation_;
}

ReferenceSnapshot ProgressiveReference::snapshot() const {
  std::lock_guard lock(mutex_);
  return snapshot_;
}

std::string ProgressiveReference::error() const {
  std::lock_guard lock(mutex_);
  return error_;
}

void ProgressiveReference::run() {
  for (;;) {
    ReferenceJob job;
    std::uint64_t generation = 0;
    int batch = 0;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return quit_ || (has_job_ && snapshot_.samples_per_pixel < max_samples_ && error_.empty()); });
      if (quit_) return;
      job = job_;
      generation = generation_;
      batch = snapshot_.batches;
    }
    // Each batch draws an independent sample set (its own seed), so the batch means are
    // independent estimates of V and their spread gives the standard error of their mean.
    RaytracedParams params;
    params.samples = batch_samples_;
    ReferenceImage out;
    try {
      const std::uint32_t seed = hash_combine(job.seed, static_cast<std::uint32_t>(batch));
      out = render_reference(*job.scene, *job.gbuffer, job.spec, params, seed);
    } catch (const std::exception& e) {
      std::lock_guard lock(mutex_);
      if (generation == generation_) error_ = e.what();
      continue;
    }
    std::lock_guard lock(mutex_);
    if (generation != generation_) continue;  // the view changed while this batch ran
    const GBuffer& g = *job.gbuffer;
    const int n = batch + 1;
    ReferenceSnapshot& s = snapshot_;
    if (s.visibility.empty()) s.visibility = Image<float>(g.width(), g.height(), 1.0f);
    double sum_se = 0;
    std::size_t covered = 0;
    for (std::size_t i = 0; i < g.object_id.size(); ++i) {
      if (!g.covered(i)) continue;
      const double v = out.scalar.visibility[i];
      sum_[i] += v;
      sum_sq_[i] += v * v;
      s.visibility[i] = static_cast<float>(sum_[i] / n);
      if (n >= 2) {
        const double var = std::max(0.0, (sum_sq_[i] - sum_[i] * sum_[i] / n) / (n - 1));
        sum_se += std::sqrt(var / n);
      }
      ++covered;
    }
    s.batches = n;
    s.samples_per_pixel = n * batch_samples_;
    if (n >= 2) s.mean_std_error = covered > 0 ? sum_se / static_cast<double>(covered) : 0.0;
    s.version = version_.load() + 1;
    version_.store(s.version, std::memory_order_release);
  }
}

}  // namespace ao::view
