#include "ao/reference/ray_scene.h"

#include <cstdint>
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

RayScene::RayScene(const Scene& scene, const BvhOptions& options)
    : source_(scene), bounds_(scene.bounds()), handles_(std::make_unique<Handles>()) {
  RTCDevice& device = handles_->device;
  RTCScene& bvh = handles_->scene;
  device = rtcNewDevice(nullptr);
  if (!device) throw SystemError("embree: cannot create a device (does this CPU support SSE2?)");
  rtcSetDeviceErrorFunction(device, on_embree_error, nullptr);
  if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)) packet_width_ = 16;
  else if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED)) packet_width_ = 8;
  else if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED)) packet_width_ = 4;

  // The size rule of kCompactBvhTriangles (measured in BENCHMARKS.md, "Loading big meshes").
  const bool big = scene.triangle_count() > kCompactBvhTriangles;
  quality_ = options.quality.value_or(big ? BvhQuality::Medium : BvhQuality::High);
  compact_ = options.compact.value_or(big);
  bvh = rtcNewScene(device);
  rtcSetSceneBuildQuality(bvh, quality_ == BvhQuality::High ? RTC_BUILD_QUALITY_HIGH
                               : quality_ == BvhQuality::Medium ? RTC_BUILD_QUALITY_MEDIUM
                                                                : RTC_BUILD_QUALITY_LOW);
  if (compact_) rtcSetSceneFlags(bvh, RTC_SCENE_FLAG_COMPACT);
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    const Mesh& m = scene.meshes[i];
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Embree's SIMD loads read 16 bytes from the last vertex, 4 past its end: the mesh's own array
    // is shared when its spare capacity covers that (validate_and_prepare reserves it), else copied
    // into a buffer Embree pads itself.
    if (m.positions.capacity() >= m.positions.size() + kVertexPadding) {
      rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, m.positions.data(), 0, sizeof(Vec3), m.positions.size());
    } else {
      auto* v = static_cast<Vec3*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, sizeof(Vec3), m.positions.size()));
      check(device, "allocating a vertex buffer");
      std::memcpy(v, m.positions.data(), m.positions.size() * sizeof(Vec3));
    }
    // Indices are read one triangle (12 bytes) at a time: no padding needed.
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, m.indices.data(), 0, 3 * sizeof(std::uint32_t), m.triangle_count());
    check(device, "setting geometry buffers");
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
