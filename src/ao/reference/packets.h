// Compile-time mapping from a packet width to Embree 3's packet types and calls, so kernels are
// written once for 4-, 8- and 16-wide packets and pick the width the CPU supports at run time.
#pragma once

#include <embree3/rtcore.h>

namespace ao::detail {

template <int N>
struct Packet;

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
