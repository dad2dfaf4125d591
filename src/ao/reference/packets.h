// Compile-time mapping from a packet width to Embree 3's packet types and calls, so kernels are
// written once for 4-, 8- and 16-wide packets and pick the width the CPU supports at run time.
#pragma once

#include <embree3/rtcore.h>
#include <pmmintrin.h>
#include <xmmintrin.h>

namespace ao::detail {

/// Embree asks for flush-to-zero and denormals-are-zero on every thread that traces (denormal
/// arithmetic in traversal is slow). Kernels call this at the start of each parallel task: two
/// register writes, cheaper than tracking which pool threads have it already.
inline void flush_denormals_to_zero() {
  _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
  _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

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
