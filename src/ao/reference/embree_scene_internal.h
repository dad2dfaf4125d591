// Internal: the Embree objects behind a RayScene, for the ray kernels of reference/, gbuffer/ and
// bake/. Not installed; programs using the library never see an Embree type.
#pragma once

#include <embree3/rtcore.h>

#include "ao/reference/ray_scene.h"

namespace ao {

struct RayScene::Handles {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
};

/// The committed Embree scene of `rs`: mesh i is geometry i.
inline RTCScene embree_scene(const RayScene& rs) { return rs.handles().scene; }

}  // namespace ao
