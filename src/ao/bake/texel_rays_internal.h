// SPDX-License-Identifier: Apache-2.0
// Pieces shared by the inside-out bakers (raytraced_bake.cpp, high_to_low.cpp): a texel's patch of
// surface as sub-triangles for sampling points by area, the ray tracer that turns a batch of rays
// into mu(D), the lane-parallel ray maker (make_texel_rays, TexelPoints) of the ray-traced baker,
// and the bakers' one tile loop (for_each_texel_patch). Internal to src/ao/bake (namespace detail).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "ao/bake/bake_result.h"
#include "ao/bake/denoise.h"
#include "ao/bake/texel_coverage.h"
#include "ao/core/membership.h"
#include "ao/core/parallel.h"
#include "ao/core/progress.h"
#include "ao/core/sampling.h"
#include "ao/reference/embree_scene_internal.h"
#include "ao/reference/mean_accumulator_internal.h"
#include "ao/reference/packets_internal.h"
#include "ao/reference/ray_offset.h"
#include "ao/reference/ray_scene.h"
#include "ao/reference/ray_tiles_internal.h"

namespace ao::detail {

/// Geometric (face) normal of every triangle, per mesh, in the mesh's own coordinates (world
/// space, but for an instanced mesh; hit_face_normal moves it to the world).
struct TriangleNormals {
  std::vector<std::vector<Vec3>> per_mesh;
};

/// World-space face normal (not unit for an instance) of the triangle a ray hit (Embree's hit
/// fields; u and v find the triangle in a quad BVH).
inline Vec3 hit_face_normal(const RayScene& rs, const TriangleNormals& fn, unsigned geom_id, unsigned inst_id, unsigned prim_id, float u, float v) {
  const HitRef h = resolve(rs, geom_id, inst_id, prim_id, u, v);
  const Vec3 n = fn.per_mesh[h.mesh][h.triangle];
  return h.normal_to_world ? h.normal_to_world->vector(n) : n;
}
TriangleNormals face_normals(const Scene& s);

/// One sub-triangle of a texel's patch (a fan triangle of a mesh triangle clipped to the texel),
/// with what a sample needs at its three corners. Position, interpolated normal and barycentrics
/// are affine in UV over a mesh triangle, so at a point with corner weights w they are the
/// w-weighted sums of the corner values: no barycentric solve per sample.
struct PatchPiece {
  // A user-provided constructor, so that out.emplace_back() does not value-initialise (zero all
  // 136 bytes with rep stos: 12% of build_patch) a piece whose every field build_patch then sets;
  // mesh, triangle, offset and cdf start unset, the Vec3s at 0.
  PatchPiece() {}  // NOLINT(modernize-use-equals-default)
  std::uint32_t mesh, triangle;
  std::array<Vec3, 3> p;     ///< World positions of the corners.
  std::array<Vec3, 3> n;     ///< Interpolated vertex normals at the corners (not normalised: normalise after weighting).
  std::array<Vec3, 3> bary;  ///< Barycentrics (l0, l1, l2) of the corners in the mesh triangle.
  Vec3 ng;                   ///< Face normal, unit.
  float offset;              ///< Scale-free ray origin offset of the mesh triangle (reference/ray_offset.h), world units.
  float cdf;                 ///< Cumulative world area of the texel's pieces up to and including this one.
};
/// The pieces of a texel of `cov` (computed on `s`) whose fragments are `fragments` (texel_fragments,
/// bin_fragments), in fragment order. `fn` = face_normals(s).
void build_patch(const Scene& s, const TexelCoverage& cov, const TriangleNormals& fn, std::span<const TexelPiece> fragments,
                 std::vector<PatchPiece>& out);

/// What a texel's patch was built from: the scene, the map's coverage computed on it, and its face
/// normals (face_normals).
struct TexelSource {
  const Scene& scene;
  const TexelCoverage& cov;
  const TriangleNormals& fn;
};

/// The point of texel `texel`'s surface under its centre, as a patch of one piece whose three
/// corners are that point and whose area is the whole patch's (`patch`, non-empty), so that every
/// sample of it starts there: the fragment whose UV triangle holds the centre, else the point of a
/// fragment's triangle nearest to the centre in UV (a texel on a chart's border whose centre lies
/// outside the chart).
/// `fragments`: the texel's (texel_fragments).
void centre_patch(const TexelSource& texels, std::size_t texel, std::span<const TexelPiece> fragments, const std::vector<PatchPiece>& patch,
                  std::vector<PatchPiece>& out);

/// The area-weighted centroid and unit mean normal of a non-empty patch (of the face normals when
/// `geometric`, else of the interpolated normals; the first piece's face normal where they cancel):
/// where denoise_map finds the texel on the surface.
void patch_guide(const std::vector<PatchPiece>& patch, bool geometric, Vec3& position, Vec3& normal);

/// A point of a patch: its piece and the weights of the piece's corners (summing to 1).
struct PatchSample {
  const PatchPiece* piece;
  Vec3 w;
  Vec3 position() const { return piece->p[0] * w.x + piece->p[1] * w.y + piece->p[2] * w.z; }
  /// Unit interpolated normal; the face normal where the vertex normals cancel.
  Vec3 normal() const {
    const Vec3 n = piece->n[0] * w.x + piece->n[1] * w.y + piece->n[2] * w.z;
    const float len = length(n);
    return len > 1e-6f ? n / len : piece->ng;
  }
  Vec3 barycentrics() const { return piece->bary[0] * w.x + piece->bary[1] * w.y + piece->bary[2] * w.z; }
};

/// A uniform-by-area point of a non-empty patch for u in [0,1)^2: the piece is chosen by world area
/// from u.x, u.x is rescaled within the piece (keeping the stratification of u), and the point is
/// uniform in the piece's triangle.
inline PatchSample sample_patch(const std::vector<PatchPiece>& patch, Vec2 u) {
  const float target = u.x * patch.back().cdf;
  std::size_t pi = 0;
  while (pi + 1 < patch.size() && patch[pi].cdf <= target) ++pi;
  const float lo = pi == 0 ? 0.0f : patch[pi - 1].cdf;
  const float span = patch[pi].cdf - lo;
  const float su = span > 0 ? std::clamp((target - lo) / span, 0.0f, 1.0f) : 0.0f;
  // Uniform point of triangle a b c: a + sqrt(s) ((1 - t)(b - a) + t (c - a)), i.e. corner
  // weights (1 - r, r (1 - t), r t) with r = sqrt(s).
  const float r = std::sqrt(su);
  return {&patch[pi], {1.0f - r, r * (1.0f - u.y), r * u.y}};
}

/// The patch with its normals turned over (interpolated and face normals negated): what the
/// inside hemisphere's rays leave from.
inline void turn_over(const std::vector<PatchPiece>& patch, std::vector<PatchPiece>& out) {
  out = patch;
  for (PatchPiece& p : out) {
    for (Vec3& n : p.n) n = -n;
    p.ng = -p.ng;
  }
}

/// The radius, sin(angle / 2), of the disk whose lift (Malley's method) is the cone of full angle
/// `spread_angle` degrees about the normal.
inline float cone_disk_radius(float spread_angle) { return spread_angle >= 180.0f ? 1.0f : std::sin(spread_angle * (kPi / 360.0f)); }

/// Direction uniforms for the cone whose disk radius is `radius`: the concentric map takes the
/// square [0,1)^2 scaled about its centre by `radius` onto the disk of that radius (it keeps the
/// angle and scales the radius of each point), whose lift is the cosine-weighted distribution
/// restricted to the cone. Stratification carries over unchanged.
inline Vec2 narrow_to_cone(Vec2 u, float radius) { return {0.5f + (u.x - 0.5f) * radius, 0.5f + (u.y - 0.5f) * radius}; }
/// The same for lanes 0 .. count - 1 of dimensions 0-1 of u (dimensions 2-3 copied).
inline void narrow_to_cone(const float (&u)[4][16], int count, float radius, float (&out)[4][16]) {
  for (int k = 0; k < count; ++k) {
    const Vec2 c = narrow_to_cone(Vec2{u[0][k], u[1][k]}, radius);
    out[0][k] = c.x;
    out[1][k] = c.y;
    out[2][k] = u[2][k];
    out[3][k] = u[3][k];
  }
}

/// Up to 16 rays of one texel, laid out as an RTCRay16's origins and directions (structure of
/// arrays, one lane per ray).
struct TexelRayBatch {
  static constexpr int kWidth = 16;
  // Zero at first: lanes past a batch's count keep what an earlier batch left there, finite.
  alignas(64) float ox[kWidth]{}, oy[kWidth]{}, oz[kWidth]{};
  alignas(64) float dx[kWidth]{}, dy[kWidth]{}, dz[kWidth]{};
  alignas(64) int valid[kWidth]{};  ///< -1: a ray to trace; 0: no ray (a direction below the face, mu = 0, or a lane past the count).
};

/// Which Owen-scrambled Sobol sequence a texel's samples come from, and where in it. The texels of
/// each 4 x 4 block of the map share one sequence (keyed by the block), and the k-th texel of the
/// block (row-major) takes its points [k n, (k + 1) n), n samples per texel: interleaved sampling
/// (Keller and Heidrich 2001) with a net in place of their regular sets. At n a power of two each
/// texel's set is an aligned block of a (0, 2)-sequence, so a (0, m, 2)-net of its own, stratified
/// as a set keyed by the texel alone would be, and unbiased (every point of an Owen-scrambled
/// sequence is uniform); the block's 16 n points are one net, so the filter, which averages
/// neighbouring texels, averages one stratified set instead of sixteen independent ones.
/// Measured (docs/methods/bake.md, "Sample sets"): the filtered map's error 0.0141 -> 0.0119 at 8
/// rays and sigma 3, 0.00562 -> 0.00525 at the default 64; the unfiltered one the same.
struct TexelSampleSet {
  std::uint32_t key;    ///< The block's sequence (sobol_owen_4d's seed).
  std::uint32_t first;  ///< Index of the texel's first point in it.
};
constexpr int kSampleBlock = 4;  ///< Texels per side of a block that shares a sequence.
inline TexelSampleSet texel_sample_set(std::uint32_t seed, int x, int y, int samples) {
  const int in_block = (y % kSampleBlock) * kSampleBlock + x % kSampleBlock;
  // samples <= 2^20 (the bakers' bound): 16 * 2^20 indices fit in 32 bits.
  return {pixel_seed(seed, x / kSampleBlock, y / kSampleBlock), static_cast<std::uint32_t>(in_block) * static_cast<std::uint32_t>(samples)};
}

/// A texel's sample points, the points of the 4-D Owen-scrambled Sobol sequence its TexelSampleSet
/// names (sobol_owen_4d; dimensions 0-1 make the direction, 2-3 the point on the patch), in
/// direction order: sorted (stably) into the cells of a grid over dimensions 0-1 with
/// about 16 points per cell (2 x 2 cells at 64 samples). The concentric map takes a cell to one
/// compact region of the hemisphere, so the 16 rays of a packet leave one texel in similar
/// directions and traverse much the same BVH nodes. Dimensions 0-1 of each aligned block of 2^m
/// points are a (0, m, 2)-net, so a power-of-two count of samples puts exactly 16 in every cell.
/// The set of samples, and so the texel's mean, is the one sobol_owen_4d gives in index order.
struct TexelPoints {
  std::vector<float> u[4];  ///< Dimension d of the j-th point in direction order.
  // The sort's scratch (unused below 32 samples: one cell, index order).
  std::vector<std::uint32_t> cell_count;
  std::vector<std::uint32_t> cell_of;  ///< Grid cell of each point in index order.
  std::vector<float> scratch[4];
  /// The texel's `samples` points of `set`.
  void generate(const TexelSampleSet& set, int samples);
  /// Points first .. first + count - 1 (count in [1, 16]) of the order into lanes 0 .. count - 1.
  void lanes(int first, int count, float (&out)[4][16]) const;
};

/// The variance of a texel's mean measured from its own samples, as a stratified estimate: the
/// samples' direction uniforms (dimensions 0-1) are binned into a grid of 2^(m-1) cells, 2^m the
/// largest power of two <= the sample count, and
///   var(mean) = sum over cells c of n_c s_c^2 / n^2,
/// s_c^2 the unbiased variance of the n_c samples in cell c (a cell with a single sample takes the
/// pooled variance of the others). Each aligned block of 2^m points of the Sobol set is a
/// (0, m, 2)-net in dimensions 0-1, so at a power-of-two count every cell holds exactly two
/// samples: the finest strata the set guarantees. The visibility varies far more across the
/// hemisphere than within one of these cells, so this measures the noise the stratified samples
/// actually have, which the plain sample variance (for mu in {0, 1}, the V (1 - V) / n bound)
/// overstates several times over.
class StratifiedVariance {
 public:
  /// Empties the sums and sizes the grid for `samples` samples (>= 1).
  void reset(int samples);
  /// The cell of a sample whose direction uniforms are (u0, u1) in [0, 1)^2.
  std::uint32_t cell(float u0, float u1) const {
    const int a = std::min(static_cast<int>(u0 * static_cast<float>(cols_)), cols_ - 1);
    const int b = std::min(static_cast<int>(u1 * static_cast<float>(rows_)), rows_ - 1);
    return static_cast<std::uint32_t>(a * rows_ + b);
  }
  void add(std::uint32_t cell, double v) {
    Sums& c = cells_[cell];
    c.sum += v, c.sum_sq += v * v, ++c.n;
  }
  /// The variance of the mean of the samples added (0 with fewer than two).
  double mean_variance() const;

 private:
  struct Sums {
    double sum = 0, sum_sq = 0;
    int n = 0;
  };
  int cols_ = 1, rows_ = 1;
  std::vector<Sums> cells_;
};

/// A patch's pieces as columns of per-field rows (corner positions, corner normals, face normal,
/// ray offset, and where the piece starts in the cumulative area with 1 / its area), built once
/// per texel for make_texel_rays, which looks a lane's piece up in each row.
struct PatchTable {
  enum : int { kP = 0, kN = 9, kNg = 18, kOff = 21, kLo = 22, kInvSpan = 23, kFields = 24 };
  static constexpr int kMaxPieces = 16;  ///< Pieces the table holds; a patch with more is read piece by piece.
  alignas(64) float f[kFields][kMaxPieces];
  float fixed_offset = 0;
  /// `fixed_offset`: the user's ray offset, or 0 for each piece's scale-free one.
  void build(const std::vector<PatchPiece>& patch, float fixed_offset);
  /// The fields of piece j of `patch`.
  void piece_fields(const std::vector<PatchPiece>& patch, std::size_t j, float (&v)[kFields]) const;
};

/// The rays of `count` (in [1, 16]) samples of a texel with non-empty patch `patch` (and its
/// table), sample k from the point u[0..3][k] (as TexelPoints: dimensions 0-1 make a
/// cosine-weighted direction about the unit normal at the point, 2-3 pick the point with
/// sample_patch). The normal is the interpolated one, or the face normal when `geometric`; the
/// origin is the point pushed off along the face normal by the table's offset; a direction with
/// d . ng <= 0 is no ray, as is every lane from `count` on (only its valid flag is written beyond
/// the vectors that hold the count). The same rays as sample_patch, Frame and cosine_hemisphere
/// make, computed lane-parallel: the arithmetic runs in SIMD registers across the lanes and the
/// concentric map's sine and cosine are polynomials (error under 1e-7).
void make_texel_rays(const std::vector<PatchPiece>& patch, const PatchTable& table, const float (&u)[4][16], int count, bool geometric,
                     TexelRayBatch& out);

/// Lanes 0 .. count - 1 (count in [1, 16]) of `out`: rays from `origin` in the cosine-weighted
/// directions about the unit normal n that u[0][k], u[1][k] make (cosine_hemisphere's concentric
/// map in Frame::from_normal(n), with make_texel_rays' polynomial sine and cosine), a lane's ray
/// valid where its direction is above the plane of the unit face normal ng (below it: occluded by
/// the surface itself, mu = 0, no ray); lanes from count on are not valid, and keep the origin and
/// direction an earlier call left there.
void make_hemisphere_rays(Vec3 origin, Vec3 n, Vec3 ng, const float (&u)[4][16], int count, TexelRayBatch& out);

/// Where the search for the next hit starts along ray o + t d after a face hit at t with normal
/// n (any length): past the face's plane by the ray-offset distance of the hit point's coordinates
/// (ray_offset.h), measured along the ray. Embree's t is known to a few float spacings of those
/// coordinates, not of t, so starting one spacing of t beyond it can find the same face again.
inline float beyond_face(Vec3 o, Vec3 d, float t, Vec3 n) {
  const float cos = std::abs(dot(n, d)) / std::sqrt(dot(n, n) * dot(d, d));
  // The cosine's floor keeps a grazing ray's step under 1000 offsets (0.8% of the coordinates' magnitude).
  return t + ray_offset_distance(max_abs_coordinate(o + d * t)) / std::max(cos, 1e-3f);
}

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
      const Vec3 n = hit_face_normal(rs, normals, rh.hit.geomID, rh.hit.instID[0], rh.hit.primID, rh.hit.u, rh.hit.v);
      if (!ignore_back || dot(n, d) <= 0) return falloff.mu(rh.ray.tfar);
      tnear = beyond_face(o, d, rh.ray.tfar, n);  // a back face: look beyond it
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
          } else if (ignore_back && dot(hit_face_normal(rs, normals, rh.hit.geomID[k], rh.hit.instID[0][k], rh.hit.primID[k], rh.hit.u[k], rh.hit.v[k]), dir[k]) > 0) {
            mu[k] = trace1(ctx, org[k], dir[k], beyond_face(org[k], dir[k], rh.ray.tfar[k], hit_face_normal(rs, normals, rh.hit.geomID[k], rh.hit.instID[0][k], rh.hit.primID[k], rh.hit.u[k], rh.hit.v[k])));
          } else {
            mu[k] = falloff.mu(rh.ray.tfar[k]);
          }
        }
      }
    }
  }
};

/// Traces the rays of a texel's batch (TexelRayBatch) with a Tracer in packets of the scene's
/// native width N, keeping the fixed fields of a 16-wide occlusion packet from batch to batch.
template <int N>
class BatchTracer {
 public:
  explicit BatchTracer(const Tracer& tracer) : tracer_(tracer) {
    for (int k = 0; k < 16; ++k) set_ray(packet_, k, {0, 0, 0}, {0, 0, 1}, tracer.falloff.reach());
    if constexpr (N > 1 && N < 16)
      for (int k = 0; k < N; ++k) set_ray(narrow_, k, {0, 0, 0}, {0, 0, 1}, tracer.falloff.reach());
  }

  /// mu of lanes 0 .. count - 1 of `batch` (count in [1, 16]) into mu[k]: 0 where valid[k] is 0
  /// (no ray). `as_packet`: with 16-wide packets and an occlusion-only tracer, the batch goes to
  /// Embree as it is, one packet whose valid lanes may have gaps; otherwise the valid lanes are
  /// packed, in order, into packets of N (an occlusion-only tracer's straight from the batch).
  template <class Batch>  // TexelRayBatch, or any layout of its arrays with at least its 16 lanes
  void trace(RTCIntersectContext& ctx, const Batch& batch, int count, bool as_packet, float (&mu)[16]) {
    const float reach = tracer_.falloff.reach();
    if constexpr (N == 16) {
      if (as_packet && tracer_.falloff.membership == Membership::Step && !tracer_.ignore_back) {
        // tfar is reset, as Embree sets it to -infinity for an occluded lane; mu is 1 for a lane
        // with nothing within reach.
        for (int k = 0; k < 16; ++k) {
          packet_.org_x[k] = batch.ox[k], packet_.org_y[k] = batch.oy[k], packet_.org_z[k] = batch.oz[k];
          packet_.dir_x[k] = batch.dx[k], packet_.dir_y[k] = batch.dy[k], packet_.dir_z[k] = batch.dz[k];
          packet_.tfar[k] = reach;
        }
        rtcOccluded16(batch.valid, embree_scene(tracer_.rs), &ctx, &packet_);
        for (int k = 0; k < 16; ++k) mu[k] = batch.valid[k] != 0 && packet_.tfar[k] >= 0 ? 1.0f : 0.0f;
        return;
      }
    }
    if constexpr (N > 1 && N < 16) {
      if (tracer_.falloff.membership == Membership::Step && !tracer_.ignore_back) {
        trace_narrow(ctx, batch, count, reach, mu);
        return;
      }
    }
    int live = 0;
    for (int k = 0; k < count; ++k)
      if (batch.valid[k]) {
        org_[static_cast<std::size_t>(live)] = {batch.ox[k], batch.oy[k], batch.oz[k]};
        dir_[static_cast<std::size_t>(live)] = {batch.dx[k], batch.dy[k], batch.dz[k]};
        ++live;
      }
    constexpr int step = N == 1 ? 16 : N;
    for (int at = 0; at < live; at += step) tracer_.template trace<N>(ctx, org_.data() + at, dir_.data() + at, std::min(step, live - at), mu_.data() + at);
    for (int k = 0, j = 0; k < 16; ++k) mu[k] = k < count && batch.valid[k] ? mu_[static_cast<std::size_t>(j++)] : 0.0f;
  }

 private:
  // An occlusion-only batch in packets of N < 16: the valid lanes packed in order into packets
  // whose fixed fields were set once, a packet's unused lanes repeating its first ray, not valid
  // (the packets Tracer::trace makes, without its per-ray copies).
  template <class Batch>
  void trace_narrow(RTCIntersectContext& ctx, const Batch& batch, int count, float reach, float (&mu)[16]) {
    int lane_of[16];
    int live = 0;
    for (int k = 0; k < 16; ++k) {
      mu[k] = 0.0f;
      if (k < count && batch.valid[k]) lane_of[live++] = k;
    }
    alignas(64) std::array<int, N> valid;
    for (int at = 0; at < live; at += N) {
      const int c = std::min(N, live - at);
      for (int j = 0; j < N; ++j) {
        const int s = lane_of[at + (j < c ? j : 0)];
        narrow_.org_x[j] = batch.ox[s], narrow_.org_y[j] = batch.oy[s], narrow_.org_z[j] = batch.oz[s];
        narrow_.dir_x[j] = batch.dx[s], narrow_.dir_y[j] = batch.dy[s], narrow_.dir_z[j] = batch.dz[s];
        narrow_.tfar[j] = reach;
        valid[static_cast<std::size_t>(j)] = j < c ? -1 : 0;
      }
      Packet<N>::occluded(valid.data(), embree_scene(tracer_.rs), &ctx, &narrow_);
      for (int j = 0; j < c; ++j) mu[lane_of[at + j]] = narrow_.tfar[j] < 0 ? 0.0f : 1.0f;
    }
  }

  struct NoPacket {};
  const Tracer& tracer_;
  alignas(64) std::conditional_t<(N > 1 && N < 16), typename Packet<(N > 1 && N < 16 ? N : 4)>::Ray, NoPacket> narrow_;
  alignas(64) RTCRay16 packet_;
  std::array<Vec3, 16> org_, dir_;
  std::array<float, 16> mu_;
};

/// The rays of consecutive texels traced together in full packets. A call into Embree costs a
/// fixed share of traversal besides its rays (about 0.5 us on the elephant's 1024^2 map, as much as
/// five rays), so a texel of 6 samples traced in a packet of its own pays it for 6 of 16 lanes, and
/// one of 24 for 8 lanes of its second packet. Here the texels' batches (make_texel_rays) are laid
/// end to end, sample after sample, in one stream of lanes, which is traced 16 lanes at a time
/// (the last lanes at flush); each sample's mu is handed back (to consumer.sample) in the order
/// the samples came, and each texel's end (consumer.texel_done) after its last sample, so that
/// whatever sums a texel makes of its samples' mu are the sums it made tracing alone. A lane with
/// no ray (a direction below the face) stays in the stream, not valid: mu = 0.
template <int N>
class PackedTracer {
 public:
  /// A sample handed back: its mu, its tag (the caller's: its stratum), and its ray's direction
  /// (kept only with `keep_directions`; a sample with no ray: anything).
  struct Sample {
    float mu;
    std::uint32_t tag;
    Vec3 dir;
  };

  /// `as_packet`: BatchTracer::trace's (a packet goes to Embree as it is).
  PackedTracer(const Tracer& tracer, bool as_packet, bool keep_directions)
      : batch_tracer_(tracer), as_packet_(as_packet), keep_directions_(keep_directions) {}

  /// Samples 0 .. count - 1 of a texel's batch, in order, `tags[k]` each one's tag (lanes from
  /// count on not valid, as make_texel_rays and make_hemisphere_rays leave them). Traces the
  /// stream's first 16 lanes once they are filled, and hands back what they finish. (Between calls
  /// fewer than 16 lanes are filled, so a batch always fits in the stream's 32.)
  template <class Consumer>
  void add(RTCIntersectContext& ctx, const TexelRayBatch& batch, int count, const std::uint32_t* tags, Consumer& consumer) {
    // The whole batch is copied (make_texel_rays marks its lanes from count on not valid); the
    // next batch writes over the lanes past count.
    std::copy_n(batch.ox, kWidth, stream_.ox + fill_), std::copy_n(batch.oy, kWidth, stream_.oy + fill_), std::copy_n(batch.oz, kWidth, stream_.oz + fill_);
    std::copy_n(batch.dx, kWidth, stream_.dx + fill_), std::copy_n(batch.dy, kWidth, stream_.dy + fill_), std::copy_n(batch.dz, kWidth, stream_.dz + fill_);
    std::copy_n(batch.valid, kWidth, stream_.valid + fill_);
    for (int k = 0; k < count; ++k) tag_[(traced_ + static_cast<std::uint64_t>(fill_ + k)) & kRingMask] = tags[k];
    fill_ += count;
    if (fill_ >= kWidth) trace(ctx, kWidth, consumer);
  }
  /// The end of a texel's samples (it may have none: high to low's texel whose cage points all
  /// missed): consumer.texel_done(texel) once they are all handed back.
  template <class Consumer>
  void end_texel(std::uint32_t texel, Consumer& consumer) {
    ends_.push_back({texel, traced_ + static_cast<std::uint64_t>(fill_)});
    drain(consumer);
  }
  /// Traces what the stream holds and hands everything back (the end of a tile).
  template <class Consumer>
  void flush(RTCIntersectContext& ctx, Consumer& consumer) {
    if (fill_ > 0) trace(ctx, fill_, consumer);
    drain(consumer);
  }

 private:
  static constexpr int kWidth = TexelRayBatch::kWidth;
  // Samples between the last handed back and the last added: at most 2 kWidth - 1 in the stream
  // plus a batch. (Texel ends are not bounded so: any number of texels without samples may end
  // while the stream holds rays.)
  static constexpr std::uint64_t kRingMask = 63;
  struct Stream {  // two batches' worth of lanes, as TexelRayBatch lays out one
    alignas(64) float ox[2 * kWidth]{}, oy[2 * kWidth]{}, oz[2 * kWidth]{};
    alignas(64) float dx[2 * kWidth]{}, dy[2 * kWidth]{}, dz[2 * kWidth]{};
    alignas(64) int valid[2 * kWidth]{};
  };
  struct End {
    std::uint32_t texel;
    std::uint64_t at;  // the stream position after its last sample
  };

  // Traces lanes 0 .. lanes - 1 (lanes <= kWidth; those past `lanes` are not valid), moves the
  // rest of the stream down, and hands back what they finish.
  template <class Consumer>
  void trace(RTCIntersectContext& ctx, int lanes, Consumer& consumer) {
    for (int k = lanes; k < kWidth; ++k) stream_.valid[k] = 0;
    float mu[kWidth];
    batch_tracer_.trace(ctx, stream_, lanes, as_packet_, mu);
    for (int k = 0; k < lanes; ++k) {
      const std::uint64_t at = (traced_ + static_cast<std::uint64_t>(k)) & kRingMask;
      mu_[at] = mu[k];
      if (keep_directions_) dir_[at] = {stream_.dx[k], stream_.dy[k], stream_.dz[k]};
    }
    traced_ += static_cast<std::uint64_t>(lanes);
    fill_ -= lanes;
    // A whole batch's width moved down (lanes <= kWidth), not just the fill_ lanes left: a copy of
    // fixed size is a vector move, not a call; the lanes past fill_ are written over by the next
    // batch, or marked not valid by the flush, before they are traced.
    for (float* lane : {stream_.ox, stream_.oy, stream_.oz, stream_.dx, stream_.dy, stream_.dz}) std::copy_n(lane + lanes, kWidth, lane);
    std::copy_n(stream_.valid + lanes, kWidth, stream_.valid);
    drain(consumer);
  }
  // Hands back every traced sample not handed back yet, and the ends of texels among them, in order.
  template <class Consumer>
  void drain(Consumer& consumer) {
    for (;;) {
      while (ends_front_ < ends_.size() && ends_[ends_front_].at == given_) consumer.texel_done(ends_[ends_front_++].texel);
      if (ends_front_ == ends_.size()) ends_.clear(), ends_front_ = 0;
      if (given_ == traced_) return;
      const std::uint64_t at = given_++ & kRingMask;
      consumer.sample(Sample{mu_[at], tag_[at], keep_directions_ ? dir_[at] : Vec3{}});
    }
  }

  BatchTracer<N> batch_tracer_;
  bool as_packet_, keep_directions_;
  int fill_ = 0;               // lanes of the stream filled
  std::uint64_t traced_ = 0;   // stream position of lane 0: samples traced so far
  std::uint64_t given_ = 0;    // samples handed back so far
  std::vector<End> ends_;        // texel ends not handed back yet, from ends_front_ on
  std::size_t ends_front_ = 0;
  std::array<float, kRingMask + 1> mu_;
  std::array<std::uint32_t, kRingMask + 1> tag_;
  std::array<Vec3, kRingMask + 1> dir_;
  Stream stream_;
};

/// What the inside-out bakers make of a texel's samples as PackedTracer hands them back, in
/// order: the mean of mu (V), the mu-weighted sum of the ray directions (the bent normal), and
/// the variance of the mean over the strata the samples' tags name (the filter's guide), written
/// to the texel at its end. `mark_missed` (high to low): a texel none of whose samples came back
/// (no cage point found the high mesh) is marked missed instead.
class TexelSums {
 public:
  TexelSums(BakeResult& out, TexelGuides* guides, int samples, bool bent_normals, bool mark_missed)
      : out_(out), guides_(guides), samples_(samples), bent_normals_(bent_normals), mark_missed_(mark_missed) {
    if (guides_) noise_.reset(samples_);
  }
  /// The stratum (the tag of a sample) of direction uniforms (u0, u1): StratifiedVariance's cell.
  std::uint32_t stratum(float u0, float u1) const { return guides_ ? noise_.cell(u0, u1) : 0u; }

  template <class Sample>
  void sample(const Sample& s) {
    acc_.add(s.mu);  // a direction below the face (no ray) counts as occluded, mu = 0
    if (guides_) noise_.add(s.tag, s.mu);
    if (bent_normals_ && s.mu != 0.0f) bent_ += s.dir * s.mu;  // (mu = 0, no ray or an occluded one, adds nothing)
  }
  void texel_done(std::uint32_t texel) {
    if (mark_missed_ && acc_.n == 0) {
      out_.missed[texel] = 1;
    } else {
      out_.visibility[texel] = static_cast<float>(acc_.mean());
      if (bent_normals_) out_.bent_normal[texel] = normalize(bent_);
      if (guides_) guides_->variance[guides_->slot(texel)] = static_cast<float>(noise_.mean_variance());
    }
    acc_ = {};
    bent_ = {0, 0, 0};
    if (guides_) noise_.reset(samples_);
  }

 private:
  BakeResult& out_;
  TexelGuides* guides_;
  int samples_;
  bool bent_normals_, mark_missed_;
  MeanAccumulator acc_;
  StratifiedVariance noise_;
  Vec3 bent_{0, 0, 0};
};

/// Texels per tile side of the inside-out bakers' tile loop: neighbouring texels lie close on the
/// surface, so a tile's rays share BVH nodes in cache.
inline constexpr int kTexelTile = 16;
static_assert(kTexelTile % TexelCoverage::kBin == 0, "a tile of texels is whole bins of the coverage");

/// The tile loop of the inside-out bakers: every covered texel of `cov` (computed on `surface`,
/// whose face normals are `fn`) that has a non-empty patch, in tiles of kTexelTile texels traced
/// in `rs` (ray_tiles_internal.h). Each tile makes its worker, w = make_worker.template
/// operator()<N>() (its scratch: sample points, batches, packets), and calls w(ctx, x, y, texel,
/// patch, fragments) for each such texel, texel = y * width + x, fragments its texel_fragments,
/// then w.finish(ctx) at the end of the tile where the worker has one.
/// Progress is reported in covered texels. A texel's work may depend only on the texel (its
/// coordinates, its seed), so that the result is the same at any thread count.
template <class MakeWorker>
void for_each_texel_patch(const RayScene& rs, const Scene& surface, const TexelCoverage& cov, const TriangleNormals& fn, const ProgressFn& progress,
                          MakeWorker&& make_worker) {
  ProgressCounter counter(progress, cov.covered_texels);
  // Tiles on the grid of kTexelTile (blocks_of_tiles), so that each is whole bins of the coverage.
  const RayTiling tiling{.tile_width = kTexelTile, .tile_height = kTexelTile, .blocks_of_tiles = true};
  for_each_ray_tile(rs, cov.width, cov.height, tiling, counter, [&]<int N>(RTCIntersectContext& ctx, const Tile& t) {
    auto worker = make_worker.template operator()<N>();
    std::vector<PatchPiece> patch;
    BinFragments bin;
    std::size_t covered = 0;
    for_each_covered_texel(surface, cov, t.x0, t.y0, t.x1, t.y1, bin, [&](int x, int y, std::size_t texel, std::span<const TexelPiece> fragments) {
      ++covered;
      build_patch(surface, cov, fn, fragments, patch);
      if (!patch.empty()) worker(ctx, x, y, texel, patch, fragments);
    });
    if constexpr (requires { worker.finish(ctx); }) worker.finish(ctx);  // a worker that holds texels back (PackedTracer)
    return covered;
  });
}

}  // namespace ao::detail
