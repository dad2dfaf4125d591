// RayScene: a Scene built into an Embree 3 BVH. Embree is used only behind this header (and by
// the kernels in reference/ and gbuffer/ that include it).
#pragma once

#include <embree3/rtcore.h>

#include "ao/scene/mesh.h"

namespace ao {

class RayScene {
 public:
  /// Builds the BVH for `scene`, which must outlive this object and have passed
  /// validate_and_prepare. Mesh i becomes Embree geometry i.
  explicit RayScene(const Scene& scene);
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  RTCScene handle() const { return scene_; }
  const Scene& scene() const { return source_; }
  const Bounds3& bounds() const { return bounds_; }

  /// Widest ray packet (16, 8, 4 or 1) this Embree build supports natively on this CPU.
  int native_packet_width() const { return packet_width_; }

  /// Distance to move a ray origin off the surface along the normal so that it does not hit the
  /// triangle it starts on: 1e-5 of the scene's diagonal. That is about a hundred times the
  /// float rounding of positions in a scene of that size, and far below any feature that matters.
  float self_intersection_offset() const { return 1e-5f * bounds_.diagonal(); }

 private:
  const Scene& source_;
  Bounds3 bounds_;
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  int packet_width_ = 1;
};

}  // namespace ao
