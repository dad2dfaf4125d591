#include "ao/reference/ray_scene.h"

#include <cstring>
#include <string>

#include "ao/core/error.h"
#include "ao/reference/embree_scene_internal.h"

namespace ao {

namespace {

void on_embree_error(void* /*user*/, RTCError code, const char* message) {
  // Embree reports allocation failures and API misuse here; they surface as SystemError from
  // the calls below (rtcGetDeviceError), so nothing is thrown across Embree's C frames.
  (void)code;
  (void)message;
}

void check(RTCDevice device, const char* what) {
  const RTCError e = rtcGetDeviceError(device);
  if (e != RTC_ERROR_NONE) throw SystemError(std::string("embree: ") + what + " failed (error " + std::to_string(static_cast<int>(e)) + ")");
}

}  // namespace

RayScene::RayScene(const Scene& scene) : source_(scene), bounds_(scene.bounds()), handles_(std::make_unique<Handles>()) {
  RTCDevice& device = handles_->device;
  RTCScene& bvh = handles_->scene;
  device = rtcNewDevice(nullptr);
  if (!device) throw SystemError("embree: cannot create a device (does this CPU support SSE2?)");
  rtcSetDeviceErrorFunction(device, on_embree_error, nullptr);
  if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)) packet_width_ = 16;
  else if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED)) packet_width_ = 8;
  else if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED)) packet_width_ = 4;

  bvh = rtcNewScene(device);
  rtcSetSceneBuildQuality(bvh, RTC_BUILD_QUALITY_HIGH);
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    const Mesh& m = scene.meshes[i];
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Embree-owned buffers: Embree pads them so its SIMD loads may read past the last element.
    auto* v = static_cast<float*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, sizeof(Vec3), m.positions.size()));
    auto* t = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), m.triangle_count()));
    check(device, "allocating geometry buffers");
    std::memcpy(v, m.positions.data(), m.positions.size() * sizeof(Vec3));
    std::memcpy(t, m.indices.data(), m.indices.size() * sizeof(unsigned));
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(bvh, geom, static_cast<unsigned>(i));
    rtcReleaseGeometry(geom);
  }
  rtcCommitScene(bvh);
  check(device, "building the BVH");
}

RayScene::~RayScene() {
  if (handles_->scene) rtcReleaseScene(handles_->scene);
  if (handles_->device) rtcReleaseDevice(handles_->device);
}

}  // namespace ao
