// RayScene: a Scene built into a BVH for ray queries. Embree does the work, but no Embree type
// appears here: kernels in reference/, gbuffer/ and bake/ reach the Embree scene through the
// internal header ao/reference/embree_scene_internal.h, which is not part of the installed API.
#pragma once

#include <memory>

#include "ao/scene/mesh.h"

namespace ao {

class RayScene {
 public:
  /// Builds the BVH for `scene`, which must outlive this object and have passed
  /// validate_and_prepare. Mesh i becomes geometry i. Throws SystemError when Embree fails.
  explicit RayScene(const Scene& scene);
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  const Scene& scene() const { return source_; }
  const Bounds3& bounds() const { return bounds_; }

  /// Widest ray packet (16, 8, 4 or 1) this Embree build supports natively on this CPU.
  int native_packet_width() const { return packet_width_; }

  /// Embree's device and scene; defined in ao/reference/embree_scene_internal.h (internal).
  struct Handles;
  const Handles& handles() const { return *handles_; }

 private:
  const Scene& source_;
  Bounds3 bounds_;
  std::unique_ptr<Handles> handles_;
  int packet_width_ = 1;
};

}  // namespace ao
