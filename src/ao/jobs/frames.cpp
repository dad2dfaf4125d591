#include "ao/jobs/frames.h"

#include "ao/core/error.h"
#include "ao/jobs/render.h"
#include "ao/reference/ray_scene.h"

namespace ao {

FrameRenderer::FrameRenderer(PreparedScene scene) : scene_(std::move(scene)) {}

const GBuffer& FrameRenderer::render_gbuffer(const Camera& camera, const GBufferOptions& options, const ProgressFn& progress) {
  camera.validate();
  if (gbuffer_ && gbuffer_.use_count() == 1)
    ao::render_gbuffer(*scene_.rays, camera, options, *gbuffer_, progress);
  else
    gbuffer_ = std::make_shared<GBuffer>(ao::render_gbuffer(*scene_.rays, camera, options, progress));
  return *gbuffer_;
}

MethodOutput FrameRenderer::run(const MethodInfo& method, const nlohmann::json& params, const Falloff& falloff, std::uint32_t seed,
                                const ProgressFn& progress) {
  if (!gbuffer_) throw std::logic_error("FrameRenderer::run before render_gbuffer");
  return run_method(method, params, *gbuffer_, &scene_, falloff, seed, &cache_, progress);
}

}  // namespace ao
