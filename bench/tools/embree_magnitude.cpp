// SPDX-License-Identifier: Apache-2.0
// How large may coordinates be before Embree 3 gives wrong hits? (BENCHMARKS.md, "Input limits").
// A cube of half-side s (12 triangles), seen from (3s, 2s, 4s): 4096 primary rays (16-wide
// packets, unit directions) at its middle, each checked against an exact slab test in double
// precision, and 4096 ambient-occlusion rays from just above its +z face (offset 1e-5 x diagonal,
// reach 0.1 x diagonal) that must all miss, since the cube is convex.
//   ao_embree_magnitude        prints one line per half-side from 1 to 1e17
#include <embree3/rtcore.h>

#include <cmath>
#include <cstdio>
#include <algorithm>
#include <initializer_list>
#include <random>
#include <utility>

namespace {

RTCScene make_cube(RTCDevice device, double s) {
  RTCScene scene = rtcNewScene(device);
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);  // as RayScene
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, 8));
  auto* t = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, 12));
  for (int i = 0; i < 8; ++i) {
    v[3 * i] = static_cast<float>((i & 1 ? 1 : -1) * s);
    v[3 * i + 1] = static_cast<float>((i & 2 ? 1 : -1) * s);
    v[3 * i + 2] = static_cast<float>((i & 4 ? 1 : -1) * s);
  }
  const unsigned quads[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  for (int f = 0; f < 6; ++f) {
    const unsigned* q = quads[f];
    const unsigned tri[6] = {q[0], q[1], q[2], q[0], q[2], q[3]};
    for (int k = 0; k < 6; ++k) t[6 * f + k] = tri[k];
  }
  rtcCommitGeometry(g);
  rtcAttachGeometry(scene, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(scene);
  return scene;
}

/// Primary rays whose hit distance differs from the exact one by more than 1e-3 s.
int wrong_primary_hits(RTCScene scene, double s) {
  const double eye[3] = {3 * s, 2 * s, 4 * s};
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;  // as the G-buffer's primary rays
  int wrong = 0;
  for (int by = 0; by < 64; by += 4)
    for (int bx = 0; bx < 64; bx += 4) {
      RTCRayHit16 rh;
      int valid[16];
      double dir[16][3];
      for (int k = 0; k < 16; ++k) {
        valid[k] = -1;
        const double target[3] = {((bx + k % 4) / 63.0 - 0.5) * 1.2 * s, ((by + k / 4) / 63.0 - 0.5) * 1.2 * s, 0};
        double d[3] = {target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]};
        const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int j = 0; j < 3; ++j) dir[k][j] = static_cast<float>(d[j] / len);
        rh.ray.org_x[k] = static_cast<float>(eye[0]);
        rh.ray.org_y[k] = static_cast<float>(eye[1]);
        rh.ray.org_z[k] = static_cast<float>(eye[2]);
        rh.ray.dir_x[k] = static_cast<float>(dir[k][0]);
        rh.ray.dir_y[k] = static_cast<float>(dir[k][1]);
        rh.ray.dir_z[k] = static_cast<float>(dir[k][2]);
        rh.ray.tnear[k] = 0;
        rh.ray.tfar[k] = INFINITY;
        rh.ray.mask[k] = ~0u;
        rh.ray.time[k] = 0;
        rh.ray.flags[k] = 0;
        rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      }
      rtcIntersect16(valid, scene, &ctx, &rh);
      for (int k = 0; k < 16; ++k) {
        // Exact entry distance into the box [-s, s]^3 from the float origin along the float direction.
        double t0 = 0, t1 = INFINITY;
        const double org[3] = {static_cast<float>(eye[0]), static_cast<float>(eye[1]), static_cast<float>(eye[2])};
        for (int j = 0; j < 3; ++j) {
          const float lo = static_cast<float>(-s), hi = static_cast<float>(s);
          double a = (lo - org[j]) / dir[k][j], b = (hi - org[j]) / dir[k][j];
          if (a > b) std::swap(a, b);
          t0 = std::max(t0, a);
          t1 = std::min(t1, b);
        }
        const bool hit = rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
        if (t0 > t1 ? hit : !(hit && std::abs(rh.ray.tfar[k] - t0) <= 1e-3 * s)) ++wrong;
      }
    }
  return wrong;
}

/// Ambient-occlusion rays above the +z face that hit something (all should miss).
int false_occlusions(RTCScene scene, double s) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(0, 1);
  const float diagonal = static_cast<float>(2 * s * std::sqrt(3.0));
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  int hits = 0;
  for (int b = 0; b < 256; ++b) {
    RTCRay16 r;
    int valid[16];
    const float px = static_cast<float>((u(rng) * 1.8 - 0.9) * s), py = static_cast<float>((u(rng) * 1.8 - 0.9) * s);
    const float pz = static_cast<float>(s) + 1e-5f * diagonal;
    for (int k = 0; k < 16; ++k) {
      valid[k] = -1;
      const float phi = 6.2831853f * u(rng), c = std::sqrt(u(rng)), sn = std::sqrt(1 - c * c);
      r.org_x[k] = px;
      r.org_y[k] = py;
      r.org_z[k] = pz;
      r.dir_x[k] = sn * std::cos(phi);
      r.dir_y[k] = sn * std::sin(phi);
      r.dir_z[k] = c;
      r.tnear[k] = 0;
      r.tfar[k] = 0.1f * diagonal;
      r.mask[k] = ~0u;
      r.time[k] = 0;
      r.flags[k] = 0;
    }
    rtcOccluded16(valid, scene, &ctx, &r);
    for (int k = 0; k < 16; ++k) hits += r.tfar[k] < 0;
  }
  return hits;
}

}  // namespace

int main() {
  RTCDevice device = rtcNewDevice(nullptr);
  for (double s : {1.0, 1e3, 1e6, 1e9, 3e9, 1e10, 1e11, 1e12, 1e13, 1e15, 1e17}) {
    RTCScene scene = make_cube(device, s);
    std::printf("half-side %7.0e: wrong primary hits %4d / 4096, false occlusions %4d / 4096\n", s, wrong_primary_hits(scene, s),
                false_occlusions(scene, s));
    rtcReleaseScene(scene);
  }
  rtcReleaseDevice(device);
}
