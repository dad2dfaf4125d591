// SPDX-License-Identifier: Apache-2.0
// The GPU backend's device and G-buffers in a library built without it (CMake AO_GPU=OFF: no EGL or
// GL headers; each *_nogpu.cpp stands in for its *_gpu.cpp): every way to get a device says so, so
// callers need no build switches of their own. Nothing else can be called without a device.
#include "ao/gpu/device.h"
#include "ao/gpu/gbuffer.h"
#include "ao/gpu/nogpu_internal.h"

namespace ao {

namespace gpu_detail {
class Context {};
}  // namespace gpu_detail

using gpu_detail::unavailable;

GpuDevice GpuDevice::open(const GpuDeviceOptions&) { unavailable(); }
GpuDevice GpuDevice::from_current_context(GlProcLoader) { unavailable(); }
const std::string& GpuDevice::renderer() const { unavailable(); }
const std::string& GpuDevice::version() const { unavailable(); }
bool GpuDevice::software() const { unavailable(); }

GpuScene GpuScene::upload(GpuDevice&, const Scene&) { unavailable(); }
const Scene& GpuScene::scene() const { unavailable(); }
GpuGBuffer GpuGBuffer::upload(GpuDevice&, const GBuffer&) { unavailable(); }
GpuGBuffer GpuGBuffer::rasterize(GpuDevice&, const GpuScene&, const Camera&, const GBufferOptions&) { unavailable(); }
GBuffer GpuGBuffer::download() const { unavailable(); }
const Camera& GpuGBuffer::camera() const { unavailable(); }
int GpuGBuffer::width() const { unavailable(); }
int GpuGBuffer::height() const { unavailable(); }
const std::vector<GpuPassTime>& GpuGBuffer::passes() const { unavailable(); }

}  // namespace ao
