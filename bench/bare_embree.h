// SPDX-License-Identifier: Apache-2.0
// An independent bare Embree 3 loop: the yardstick the G-buffer and the ray-traced reference are
// measured against (BENCHMARKS.md, "Reference against a bare Embree loop"). It shares nothing of
// ao's ray setup: its own Embree device and scene (default build settings, as a minimal program
// has), its own camera rays, its own RNG (PCG32), its own cosine directions and tangent frame, its
// own packet fill. It takes from ao only the data: the triangles, the camera's eye, target, up,
// field of view and size, R, and the ray count. What it does per pixel is the least a
// ray-traced AO image needs:
//   primary pass: one ray per pixel centre, rtcIntersect16 over 4x4 pixel blocks (coherent
//                 context), storing the hit point and Embree's geometric normal;
//   AO pass:      per hit pixel, `spp` cosine-weighted directions about that normal from a tiny
//                 offset, rtcOccluded16 packets of one pixel's rays (incoherent context), the count
//                 of unoccluded rays per pixel.
#pragma once

#include <embree3/rtcore.h>
#include <pmmintrin.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <xmmintrin.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "ao/core/camera.h"
#include "ao/scene/mesh.h"

namespace ao::bench::bare {

// PCG32 (O'Neill 2014), XSH RR output.
struct Pcg32 {
  std::uint64_t state, inc;
  Pcg32(std::uint64_t seed, std::uint64_t stream) : state(0), inc((stream << 1u) | 1u) {
    next();
    state += seed;
    next();
  }
  std::uint32_t next() {
    const std::uint64_t old = state;
    state = old * 6364136223846793005ull + inc;
    const auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
    const auto rot = static_cast<std::uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }
  float uniform() { return static_cast<float>(next() >> 8) * (1.0f / 16777216.0f); }
};

struct V3 {
  float x, y, z;
};
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator*(V3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
inline float dot3(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross3(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline V3 unit(V3 a) { return a * (1.0f / std::sqrt(dot3(a, a))); }

// One pixel of the primary pass.
struct Hit {
  V3 p, n;    // world hit point, unit geometric normal facing the camera
  bool valid;
};

class Loop {
 public:
  explicit Loop(const Scene& scene) {
    device_ = rtcNewDevice(nullptr);
    scene_ = rtcNewScene(device_);
    for (const Mesh& m : scene.meshes) {
      RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, m.positions.size()));
      auto* i = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, m.triangle_count()));
      std::memcpy(v, m.positions.data(), 12 * m.positions.size());
      std::memcpy(i, m.indices.data(), 4 * m.indices.size());
      rtcCommitGeometry(g);
      rtcAttachGeometry(scene_, g);
      rtcReleaseGeometry(g);
    }
    rtcCommitScene(scene_);
    if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) throw std::runtime_error("bare loop: embree failed");
  }
  ~Loop() {
    rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
  }
  Loop(const Loop&) = delete;
  Loop& operator=(const Loop&) = delete;

  // Primary pass into `hits` (resized to width x height).
  void primary(const Camera& cam, std::vector<Hit>& hits) const {
    const int w = cam.width, h = cam.height;
    hits.resize(static_cast<std::size_t>(w) * h);
    const V3 eye{cam.eye.x, cam.eye.y, cam.eye.z};
    const V3 fwd = unit(V3{cam.target.x, cam.target.y, cam.target.z} - eye);
    const V3 right = unit(cross3(fwd, V3{cam.up.x, cam.up.y, cam.up.z}));
    const V3 up = cross3(right, fwd);
    const float th = std::tan(cam.vertical_fov_deg * 3.14159265f / 360.0f), tw = th * static_cast<float>(w) / static_cast<float>(h);
    tbb::parallel_for(tbb::blocked_range2d<int>(0, h, 32, 0, w, 32), [&](const tbb::blocked_range2d<int>& r) {
      _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
      _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
      alignas(64) RTCRayHit16 rh;
      alignas(64) int valid[16];
      for (int by = r.rows().begin(); by < r.rows().end(); by += 4)
        for (int bx = r.cols().begin(); bx < r.cols().end(); bx += 4) {
          for (int k = 0; k < 16; ++k) {
            const int x = bx + (k & 3), y = by + (k >> 2);
            valid[k] = x < r.cols().end() && y < r.rows().end() ? -1 : 0;
            const float sx = (2.0f * (static_cast<float>(x) + 0.5f) / static_cast<float>(w) - 1.0f) * tw;
            const float sy = (1.0f - 2.0f * (static_cast<float>(y) + 0.5f) / static_cast<float>(h)) * th;
            const V3 d = fwd + right * sx + up * sy;
            rh.ray.org_x[k] = eye.x, rh.ray.org_y[k] = eye.y, rh.ray.org_z[k] = eye.z;
            rh.ray.dir_x[k] = d.x, rh.ray.dir_y[k] = d.y, rh.ray.dir_z[k] = d.z;
            rh.ray.tnear[k] = 0.0f, rh.ray.tfar[k] = INFINITY, rh.ray.time[k] = 0.0f;
            rh.ray.mask[k] = ~0u, rh.ray.id[k] = 0, rh.ray.flags[k] = 0;
            rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
          }
          rtcIntersect16(valid, scene_, &ctx, &rh);
          for (int k = 0; k < 16; ++k) {
            if (!valid[k]) continue;
            Hit& out = hits[static_cast<std::size_t>(by + (k >> 2)) * w + bx + (k & 3)];
            out.valid = rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
            if (!out.valid) continue;
            const V3 d{rh.ray.dir_x[k], rh.ray.dir_y[k], rh.ray.dir_z[k]};
            V3 n = unit(V3{rh.hit.Ng_x[k], rh.hit.Ng_y[k], rh.hit.Ng_z[k]});
            if (dot3(n, d) > 0) n = n * -1.0f;
            out.p = eye + d * rh.ray.tfar[k];
            out.n = n;
          }
        }
    });
  }

  // AO pass: returns the number of unoccluded rays; `rays` gets the number traced.
  // With `visibility`, also the fraction of open rays per hit pixel (resized to width x height).
  std::uint64_t ambient_occlusion(const std::vector<Hit>& hits, int width, int height, float radius, int spp, float offset,
                                  std::uint64_t* rays, std::vector<float>* visibility = nullptr) const {
    if (visibility) visibility->assign(hits.size(), 1.0f);
    std::atomic<std::uint64_t> open{0}, traced{0};
    tbb::parallel_for(tbb::blocked_range2d<int>(0, height, 16, 0, width, 16), [&](const tbb::blocked_range2d<int>& r) {
      _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
      _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
      alignas(64) RTCRay16 ray;
      alignas(64) int valid[16];
      std::uint64_t local_open = 0, local_rays = 0;
      for (int y = r.rows().begin(); y < r.rows().end(); ++y)
        for (int x = r.cols().begin(); x < r.cols().end(); ++x) {
          const Hit& hit = hits[static_cast<std::size_t>(y) * width + x];
          if (!hit.valid) continue;
          Pcg32 rng(static_cast<std::uint64_t>(y) * width + x, 54u);
          // Tangent frame: any vector not parallel to n, crossed twice.
          const V3 helper = std::abs(hit.n.x) > 0.9f ? V3{0, 1, 0} : V3{1, 0, 0};
          const V3 t = unit(cross3(helper, hit.n)), b = cross3(hit.n, t);
          const V3 o = hit.p + hit.n * offset;
          const std::uint64_t open_before = local_open;
          for (int first = 0; first < spp; first += 16) {
            for (int k = 0; k < 16; ++k) {
              valid[k] = first + k < spp ? -1 : 0;
              const float r2 = rng.uniform(), phi = 6.28318531f * rng.uniform();
              const float s = std::sqrt(r2), z = std::sqrt(1.0f - r2);
              const V3 d = t * (s * std::cos(phi)) + b * (s * std::sin(phi)) + hit.n * z;
              ray.org_x[k] = o.x, ray.org_y[k] = o.y, ray.org_z[k] = o.z;
              ray.dir_x[k] = d.x, ray.dir_y[k] = d.y, ray.dir_z[k] = d.z;
              ray.tnear[k] = 0.0f, ray.tfar[k] = radius, ray.time[k] = 0.0f;
              ray.mask[k] = ~0u, ray.id[k] = 0, ray.flags[k] = 0;
            }
            rtcOccluded16(valid, scene_, &ctx, &ray);
            for (int k = 0; k < 16; ++k) local_open += valid[k] && ray.tfar[k] >= 0.0f;
            local_rays += static_cast<std::uint64_t>(std::min(16, spp - first));
          }
          if (visibility) (*visibility)[static_cast<std::size_t>(y) * width + x] = static_cast<float>(local_open - open_before) / static_cast<float>(spp);
        }
      open += local_open;
      traced += local_rays;
    });
    if (rays) *rays = traced.load();
    return open.load();
  }

 private:
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
};

}  // namespace ao::bench::bare
