// The GPU backend's API in a library built without it (CMake AO_GPU=OFF: no EGL or GL headers):
// every way to get a device says so, so callers need no build switches of their own. Nothing else
// can be called without a device.
#include "ao/core/error.h"
#include "ao/gpu/device.h"
#include "ao/gpu/gbuffer.h"
#include "ao/gpu/methods.h"
#include "ao/gpu/voxelize.h"

namespace ao {

namespace {
[[noreturn]] void unavailable() {
  throw SystemError("--device gpu: this ao was built without the GPU backend (CMake AO_GPU=OFF: the EGL and OpenGL headers were not found)");
}
}  // namespace

namespace gpu_detail {
class Context {};
}  // namespace gpu_detail

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

std::span<const std::string_view> gpu_method_names() { return {}; }
void check_gpu_method(std::string_view, const nlohmann::json&) { unavailable(); }
GpuMethodOutput run_gpu_method(GpuDevice&, std::string_view, const GpuMethodInput&, const nlohmann::json&) { unavailable(); }
GpuMethodOutput run_gpu_method(GpuDevice&, std::string_view, const MethodInput&, const nlohmann::json&) { unavailable(); }
VoxelGrid gpu_voxelize_world(GpuDevice&, const GpuScene&, const VoxelizeOptions&, VoxelStats*) { unavailable(); }

}  // namespace ao
