// Pieces shared by the inside-out bakers (raytraced_bake.cpp, high_to_low.cpp): a texel's patch of
// surface as sub-triangles for sampling points by area, the surface point at a UV, and the ray
// tracer that turns a batch of rays into mu(D). Internal to src/ao/bake (namespace detail).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "ao/bake/texel_coverage.h"
#include "ao/core/membership.h"
#include "ao/reference/packets_internal.h"
#include "ao/reference/embree_scene_internal.h"
#include "ao/reference/ray_scene.h"

namespace ao::detail {

/// Geometric (face) normal of every triangle, per mesh, in the mesh's own coordinates (world
/// space, but for an instanced mesh; hit_face_normal moves it to the world).
struct TriangleNormals {
  std::vector<std::vector<Vec3>> per_mesh;
};

/// World-space face normal (not unit for an instance) of the triangle a ray hit.
inline Vec3 hit_face_normal(const RayScene& rs, const TriangleNormals& fn, unsigned geom_id, unsigned inst_id, unsigned prim_id) {
  const HitRef h = resolve(rs, geom_id, inst_id, prim_id);
  const Vec3 n = fn.per_mesh[h.mesh][h.triangle];
  return h.normal_to_world ? h.normal_to_world->vector(n) : n;
}
TriangleNormals face_normals(const Scene& s);

/// A texel's patch as sub-triangles in texel-unit UV space, each with the mesh triangle it lies on
/// and its world area, for sampling points uniformly by area.
struct PatchPiece {
  std::uint32_t mesh, triangle;
  Vec2 a, b, c;
  double cdf;  ///< Cumulative world area up to and including this piece.
};
/// The pieces of texel `texel` of `cov` (computed on `s`), in fragment order.
void build_patch(const Scene& s, const TexelCoverage& cov, std::size_t texel, std::vector<PatchPiece>& out);

/// A uniform-by-area point of a non-empty patch for u in [0,1)^2: the piece is chosen by world area
/// from u.x, u.x is rescaled within the piece (keeping the stratification of u), and the point is
/// uniform in the piece's triangle. Returns the piece index and the texel-unit UV.
struct PatchSample {
  std::size_t piece;
  Vec2 uv;
};
PatchSample sample_patch(const std::vector<PatchPiece>& patch, Vec2 u);

struct SurfacePoint {
  Vec3 p;      ///< World position.
  Vec3 n;      ///< Interpolated (shading) normal, unit.
  Vec3 ng;     ///< Face normal, unit.
  Vec3 bary;   ///< Barycentrics (l0, l1, l2) of the triangle's vertices.
};
/// Point of mesh triangle `tri` at texel-unit UV `q` (barycentrics solved in UV space and clamped to the triangle).
SurfacePoint point_at_uv(const Scene& s, const TexelCoverage& cov, std::uint32_t mesh, std::uint32_t tri, Vec2 q, const TriangleNormals& fn);

/// Traces AO rays and returns mu(D) per ray, optionally passing through back faces.
struct Tracer {
  const RayScene& rs;
  const Falloff& falloff;
  const TriangleNormals& normals;  ///< Face normals of rs.scene().
  bool ignore_back;

  static constexpr int kMaxBackFaceSkips = 64;  // a ray crossing more back faces than this counts as occluded

  /// mu for one ray traced on its own (used to continue through back faces).
  float trace1(RTCIntersectContext& ctx, Vec3 o, Vec3 d, float tnear) const {
    const float reach = falloff.reach();
    for (int k = 0; k < kMaxBackFaceSkips; ++k) {
      RTCRayHit rh{};
      rh.ray = {o.x, o.y, o.z, tnear, d.x, d.y, d.z, 0.0f, reach, 0xffffffffu, 0, 0};
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(embree_scene(rs), &ctx, &rh);
      if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return 1.0f;
      if (!ignore_back || dot(hit_face_normal(rs, normals, rh.hit.geomID, rh.hit.instID[0], rh.hit.primID), d) <= 0) return falloff.mu(rh.ray.tfar);
      tnear = std::nextafter(rh.ray.tfar, kInfinity);  // a back face: look beyond it
    }
    return 0.0f;
  }

  /// mu for `count` <= N rays with their own origins (N = 1: one at a time; else one packet).
  template <int N>
  void trace(RTCIntersectContext& ctx, const Vec3* org, const Vec3* dir, int count, float* mu) const {
    const float reach = falloff.reach();
    const bool occlusion_only = falloff.membership == Membership::Step && !ignore_back;
    if constexpr (N == 1) {
      for (int k = 0; k < count; ++k) {
        if (occlusion_only) {
          RTCRay r{org[k].x, org[k].y, org[k].z, 0.0f, dir[k].x, dir[k].y, dir[k].z, 0.0f, reach, 0xffffffffu, 0, 0};
          rtcOccluded1(embree_scene(rs), &ctx, &r);
          mu[k] = r.tfar < 0 ? 0.0f : 1.0f;
        } else {
          mu[k] = trace1(ctx, org[k], dir[k], 0.0f);
        }
      }
    } else {
      if (count == 0) return;
      alignas(64) typename Packet<N>::RayHit rh;
      alignas(64) std::array<int, N> valid;
      for (int k = 0; k < N; ++k) {
        const int s = k < count ? k : 0;
        valid[k] = k < count ? -1 : 0;
        set_ray_hit(rh, k, org[s], dir[s], reach);
      }
      if (occlusion_only) {
        Packet<N>::occluded(valid.data(), embree_scene(rs), &ctx, &rh.ray);
        for (int k = 0; k < count; ++k) mu[k] = rh.ray.tfar[k] < 0 ? 0.0f : 1.0f;
      } else {
        Packet<N>::intersect(valid.data(), embree_scene(rs), &ctx, &rh);
        for (int k = 0; k < count; ++k) {
          if (rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) {
            mu[k] = 1.0f;
          } else if (ignore_back && dot(hit_face_normal(rs, normals, rh.hit.geomID[k], rh.hit.instID[0][k], rh.hit.primID[k]), dir[k]) > 0) {
            mu[k] = trace1(ctx, org[k], dir[k], std::nextafter(rh.ray.tfar[k], kInfinity));
          } else {
            mu[k] = falloff.mu(rh.ray.tfar[k]);
          }
        }
      }
    }
  }
};

}  // namespace ao::detail
