// SPDX-License-Identifier: Apache-2.0
#include "ao/reference/ray_scene.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <string>

#include "ao/core/error.h"
#include "ao/reference/embree_scene_internal.h"

namespace ao {

namespace {

// Embree reports allocation failures and API misuse to this callback, in the thread of the call
// that failed; they surface as SystemError from check() after that call (rtcGetDeviceError), so
// nothing is thrown across Embree's C frames. The message is kept for check() to quote.
thread_local std::string t_embree_message;

void on_embree_error(void* /*user*/, RTCError /*code*/, const char* message) {
  t_embree_message.clear();
  // One printable line, short: it ends up in ao's error message.
  for (const char* c = message; c != nullptr && *c != '\0' && t_embree_message.size() < 160; ++c)
    t_embree_message += std::isprint(static_cast<unsigned char>(*c)) ? *c : ' ';
}

void check(RTCDevice device, const char* what) {
  const RTCError e = rtcGetDeviceError(device);
  if (e == RTC_ERROR_NONE) return;
  std::string message = std::string("embree: ") + what + " failed: " + detail::embree_error_text(static_cast<int>(e));
  if (!t_embree_message.empty() && e != RTC_ERROR_OUT_OF_MEMORY) message += " (" + t_embree_message + ")";
  t_embree_message.clear();
  throw SystemError(message);
}

RTCBuildQuality embree_quality(BvhQuality q) {
  return q == BvhQuality::High ? RTC_BUILD_QUALITY_HIGH : q == BvhQuality::Medium ? RTC_BUILD_QUALITY_MEDIUM : RTC_BUILD_QUALITY_LOW;
}

// A committed geometry for mesh m: its triangles, or (`pairs` not null) the quads of its paired
// triangles. Embree's SIMD loads read 16 bytes from the last vertex, 4 past its end: the mesh's own
// array is shared when its spare capacity covers that (validate_and_prepare reserves it), else
// copied into a buffer Embree pads itself.
RTCGeometry mesh_geometry(RTCDevice device, const Mesh& m, const detail::TrianglePairs* pairs) {
  RTCGeometry geom = rtcNewGeometry(device, pairs ? RTC_GEOMETRY_TYPE_QUAD : RTC_GEOMETRY_TYPE_TRIANGLE);
  if (m.positions.capacity() >= m.positions.size() + kVertexPadding) {
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, m.positions.data(), 0, sizeof(Vec3), m.positions.size());
  } else {
    auto* v = static_cast<Vec3*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, sizeof(Vec3), m.positions.size()));
    check(device, "allocating a vertex buffer");
    std::memcpy(v, m.positions.data(), m.positions.size() * sizeof(Vec3));
  }
  // Indices are read one primitive (12 or 16 bytes) at a time: no padding needed.
  if (pairs)
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4, pairs->quads.data(), 0, 4 * sizeof(std::uint32_t), pairs->quad_count());
  else
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, m.indices.data(), 0, 3 * sizeof(std::uint32_t), m.triangle_count());
  check(device, "setting geometry buffers");
  rtcCommitGeometry(geom);
  return geom;
}

}  // namespace

namespace detail {

std::string embree_error_text(int code) {
  switch (code) {
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory (the scene's BVH does not fit in the memory this process may use)";
    case RTC_ERROR_UNSUPPORTED_CPU: return "this processor lacks instructions Embree needs";
    case RTC_ERROR_CANCELLED: return "cancelled";
    case RTC_ERROR_INVALID_ARGUMENT: return "Embree refused an argument (an error in ao: please report it)";
    case RTC_ERROR_INVALID_OPERATION: return "Embree refused an operation (an error in ao: please report it)";
    default: return "unknown Embree error " + std::to_string(code);
  }
}

}  // namespace detail

RayScene::RayScene(const Scene& scene, const BvhOptions& options)
    : source_(scene), bounds_(scene.bounds()), handles_(std::make_unique<Handles>()) {
  check_traceable_size(scene);
  RTCDevice& device = handles_->device;
  RTCScene& bvh = handles_->scene;
  device = rtcNewDevice(nullptr);
  // A device that could not be made leaves its error with no device (rtcGetDeviceError(NULL)).
  if (!device) throw SystemError("embree: cannot create a device: " + detail::embree_error_text(static_cast<int>(rtcGetDeviceError(nullptr))));
  rtcSetDeviceErrorFunction(device, on_embree_error, nullptr);
  if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)) packet_width_ = 16;
  else if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED)) packet_width_ = 8;
  else if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED)) packet_width_ = 4;

  // Object i (Scene::objects()) is geometry i of the top-level scene: a mesh drawn in world space
  // is a triangle (or quad) geometry there; an instanced mesh gets a committed scene of its own, built once,
  // and each of its instances is an instance geometry pointing at it.
  Handles& h = *handles_;
  h.objects = scene.objects();
  h.mesh_scenes.assign(scene.meshes.size(), nullptr);
  std::size_t top_triangles = 0;
  for (const SceneObject& o : h.objects)
    if (o.instance == SceneObject::kNoInstance) top_triangles += scene.meshes[o.mesh].triangle_count();
  // The size rule of kCompactBvhTriangles (measured in BENCHMARKS.md, "Loading big meshes"),
  // applied to each BVH's own triangles: the top level's world-space meshes, each instanced mesh's.
  const auto is_big = [](std::size_t triangles) { return triangles > kCompactBvhTriangles; };
  const bool big = is_big(top_triangles);
  quality_ = options.quality.value_or(big ? BvhQuality::Medium : BvhQuality::High);
  compact_ = options.compact.value_or(big);
  // Pairing numbers a triangle's edges 4 t + corner in 32 bits: meshes of 2^30 triangles or more
  // (12 GB of indices) stay triangles.
  quads_ = options.quads && std::all_of(scene.meshes.begin(), scene.meshes.end(), [](const Mesh& m) { return m.triangle_count() < detail::kMaxPairedTriangles; });
  // The quads of each mesh, built before any geometry shares them.
  if (quads_) {
    h.pairs.resize(scene.meshes.size());
    for (const SceneObject& o : h.objects)
      if (h.pairs[o.mesh].quads.empty()) h.pairs[o.mesh] = detail::pair_triangles(scene.meshes[o.mesh]);
  }
  const auto pairs_of = [&](std::uint32_t mesh) { return quads_ ? &h.pairs[mesh] : nullptr; };
  bvh = rtcNewScene(device);
  rtcSetSceneBuildQuality(bvh, embree_quality(quality_));
  if (compact_) rtcSetSceneFlags(bvh, RTC_SCENE_FLAG_COMPACT);
  for (std::size_t i = 0; i < h.objects.size(); ++i) {
    const SceneObject& o = h.objects[i];
    RTCGeometry geom = nullptr;
    if (o.instance == SceneObject::kNoInstance) {
      geom = mesh_geometry(device, scene.meshes[o.mesh], pairs_of(o.mesh));
    } else {
      RTCScene& sub = h.mesh_scenes[o.mesh];
      if (!sub) {
        const Mesh& m = scene.meshes[o.mesh];
        const bool sub_big = is_big(m.triangle_count());
        sub = rtcNewScene(device);
        rtcSetSceneBuildQuality(sub, embree_quality(options.quality.value_or(sub_big ? BvhQuality::Medium : BvhQuality::High)));
        if (options.compact.value_or(sub_big)) rtcSetSceneFlags(sub, RTC_SCENE_FLAG_COMPACT);
        RTCGeometry mesh_geom = mesh_geometry(device, m, pairs_of(o.mesh));
        rtcAttachGeometryByID(sub, mesh_geom, 0);
        rtcReleaseGeometry(mesh_geom);
        rtcCommitScene(sub);
        check(device, "building the BVH of an instanced mesh");
      }
      const Instance& in = scene.instances[o.instance];
      geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(geom, sub);
      rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, &in.object_to_world);
      check(device, "setting an instance");
      rtcCommitGeometry(geom);
    }
    rtcAttachGeometryByID(bvh, geom, static_cast<unsigned>(i));
    rtcReleaseGeometry(geom);
  }
  h.normal_to_world.reserve(scene.instances.size());
  for (const Instance& in : scene.instances) h.normal_to_world.push_back(cofactor(in.object_to_world));
  rtcCommitScene(bvh);
  check(device, "building the BVH");
}

RayScene::~RayScene() {
  if (handles_->scene) rtcReleaseScene(handles_->scene);
  for (RTCScene sub : handles_->mesh_scenes)
    if (sub) rtcReleaseScene(sub);
  if (handles_->device) rtcReleaseDevice(handles_->device);
}

}  // namespace ao
