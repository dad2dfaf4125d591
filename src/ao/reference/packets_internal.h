// SPDX-License-Identifier: Apache-2.0
// Compile-time mapping from a packet width to Embree 3's packet types and calls, so kernels are
// written once for 4-, 8- and 16-wide packets and pick the width the CPU supports at run time.
#pragma once

#include <embree3/rtcore.h>

#include "ao/core/math.h"
#include "ao/reference/embree_scene_internal.h"
#include "ao/simd/denormals_internal.h"

namespace ao::detail {

/// Fills lane k of a ray packet (RTCRay4/8/16): origin, direction, [0, tfar], all masks, no flags.
template <class RayN>
inline void set_ray(RayN& ray, int k, Vec3 origin, Vec3 direction, float tfar) {
  ray.org_x[k] = origin.x;
  ray.org_y[k] = origin.y;
  ray.org_z[k] = origin.z;
  ray.dir_x[k] = direction.x;
  ray.dir_y[k] = direction.y;
  ray.dir_z[k] = direction.z;
  ray.tnear[k] = 0.0f;
  ray.tfar[k] = tfar;
  ray.time[k] = 0.0f;
  ray.mask[k] = 0xffffffffu;
  ray.id[k] = static_cast<unsigned>(k);
  ray.flags[k] = 0;
}

/// The same for a ray-hit packet, with the hit cleared to "no geometry".
template <class RayHitN>
inline void set_ray_hit(RayHitN& rh, int k, Vec3 origin, Vec3 direction, float tfar) {
  set_ray(rh.ray, k, origin, direction, tfar);
  rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
}


template <int N>
struct Packet;

template <>
struct Packet<1> {  // single rays: kernels call rtcIntersect1 / rtcOccluded1 themselves
  using RayHit = RTCRayHit;
  using Ray = RTCRay;
};
template <>
struct Packet<4> {
  using RayHit = RTCRayHit4;
  using Ray = RTCRay4;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* r) { rtcIntersect4(valid, s, c, r); }
  static void occluded(const int* valid, RTCScene s, RTCIntersectContext* c, Ray* r) { rtcOccluded4(valid, s, c, r); }
};
template <>
struct Packet<8> {
  using RayHit = RTCRayHit8;
  using Ray = RTCRay8;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* r) { rtcIntersect8(valid, s, c, r); }
  static void occluded(const int* valid, RTCScene s, RTCIntersectContext* c, Ray* r) { rtcOccluded8(valid, s, c, r); }
};
template <>
struct Packet<16> {
  using RayHit = RTCRayHit16;
  using Ray = RTCRay16;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* r) { rtcIntersect16(valid, s, c, r); }
  static void occluded(const int* valid, RTCScene s, RTCIntersectContext* c, Ray* r) { rtcOccluded16(valid, s, c, r); }
};

/// Calls f.template operator()<N>() with the widest packet width the scene supports (>= 4), or
/// f.template operator()<1>() when the CPU has no packet support.
template <class F>
decltype(auto) dispatch_packet_width(int native_width, F&& f) {
  switch (native_width) {
    case 16: return f.template operator()<16>();
    case 8: return f.template operator()<8>();
    case 4: return f.template operator()<4>();
    default: return f.template operator()<1>();
  }
}

}  // namespace ao::detail
