// SPDX-License-Identifier: Apache-2.0
#include "ao/jobs/frames.h"

#include "ao/core/error.h"
#include "ao/registry/methods_gpu.h"
#include "ao/jobs/render.h"
#include "ao/jobs/render_view.h"
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

MethodOutput FrameRenderer::run(const MethodParams& params, const Falloff& falloff, std::uint32_t seed, const ProgressFn& progress) {
  if (!gbuffer_) throw std::logic_error("FrameRenderer::run before render_gbuffer");
  gpu_passes_.clear();
  if (device_ == Device::Gpu) return run_on_gpu(params, falloff, seed);
  return run_on_scene(params, *gbuffer_, &scene_, falloff, seed, &cache_, progress);
}

void FrameRenderer::set_device(Device device, GpuDevice* gpu) {
  if (device == Device::Gpu && gpu == nullptr) throw std::logic_error("FrameRenderer::set_device: the GPU device without a GpuDevice");
  if (gpu != gpu_) gpu_scene_.reset();  // the scene's copy belongs to the device it was uploaded to
  device_ = device;
  gpu_ = device == Device::Gpu ? gpu : nullptr;
}

MethodOutput FrameRenderer::run_on_gpu(const MethodParams& params, const Falloff& falloff, std::uint32_t seed) {
  check_gpu_method(params);
  const GpuGBuffer g = GpuGBuffer::upload(*gpu_, *gbuffer_);
  if (method_of(params).needs_scene && !gpu_scene_) gpu_scene_.emplace(GpuScene::upload(*gpu_, *scene_.scene));
  GpuMethodOutput out = run_gpu_method(*gpu_, GpuMethodInput{g, gpu_scene_ ? &*gpu_scene_ : nullptr, falloff, seed}, params);
  gpu_passes_ = g.passes();
  gpu_passes_.insert(gpu_passes_.end(), out.passes.begin(), out.passes.end());
  return std::move(out.output);
}

}  // namespace ao
