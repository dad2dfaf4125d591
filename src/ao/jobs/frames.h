// One scene rendered frame after frame, as a viewer (or a script rendering many views) does: the
// G-buffer of each camera, then a method on it, keeping what methods cache between frames (cone's
// voxel grid, transfer's scratch images) and reusing the G-buffer's storage while nobody else holds
// it. The same G-buffer and method calls as run_render, without the files.
#pragma once

#include <cstdint>
#include <memory>

#include <nlohmann/json.hpp>

#include "ao/core/camera.h"
#include "ao/core/gbuffer.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/jobs/inputs.h"
#include "ao/registry/registry.h"

namespace ao {

class FrameRenderer {
 public:
  explicit FrameRenderer(PreparedScene scene);

  const PreparedScene& scene() const { return scene_; }

  /// Renders the G-buffer of `camera` (validated): into the storage of the previous one when no
  /// one else holds it (shared_gbuffer), so a moving camera touches no fresh pages; else into a new one.
  const GBuffer& render_gbuffer(const Camera& camera, const GBufferOptions& options = {}, const ProgressFn& progress = {});
  /// The last G-buffer rendered; null before the first.
  const GBuffer* gbuffer() const { return gbuffer_.get(); }
  /// The last G-buffer, shared with a consumer that outlives the frame (a progressive reference);
  /// the next render_gbuffer then makes a new one unless the consumer has let go.
  std::shared_ptr<const GBuffer> shared_gbuffer() const { return gbuffer_; }

  /// `method` with canonical `params` on the last G-buffer, with the cache of this scene.
  MethodOutput run(const MethodInfo& method, const nlohmann::json& params, const Falloff& falloff, std::uint32_t seed, const ProgressFn& progress = {});

 private:
  PreparedScene scene_;
  std::shared_ptr<GBuffer> gbuffer_;
  MethodCache cache_;
};

}  // namespace ao
