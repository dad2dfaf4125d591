// SPDX-License-Identifier: Apache-2.0
// High-to-low AO baking (see high_to_low.h). Per texel T of the low mesh's map:
//   V(T) = (1/A(T)) * integral over the low patch S of V_high(h(p)) dp,
// where h(p) is where the cage ray through p first meets a front face of the high mesh and V_high
// is eq. 2 of the per-texel AO paper (with mu(D) when a distance R is set) at h with the high
// mesh's interpolated normal. Both integrals are estimated together, the area one with fewer points
// than the hemisphere one: a texel's samples are split among P stratified points p_j of S (uniform
// by area, HighToLowParams::cage_points), and each p_j's share of cosine-weighted directions about
// the high normal at h(p_j) (pdf cos/pi cancels the cosine and 1/pi), so V(T) is the plain mean of
// mu over the samples whose point's cage ray hit. V varies far less over a texel's patch than over
// the hemisphere, so a few points per texel keep the area integration at a fraction of the cage rays.
//
// The cage ray: c(p) is the cage point with p's barycentrics (the extruded or explicit cage). The
// ray runs along d = (p - c)/|p - c| (inwards) from p - f d to p + b d, f the front distance
// (--max-front, default |p - c|: the ray starts on the cage) and b the back distance (--max-back,
// default |p - c|). Where the cage meets the surface (|p - c| ~ 0) d is minus the interpolated
// smoothed normal. Back faces of the high mesh (seen from inside it) are passed through, as
// xNormal and Substance do by default, so a ray starting just inside a bump still finds the surface
// beneath it.
#include "ao/bake/high_to_low.h"

#include <array>
#include <atomic>
#include <cmath>
#include <map>

#include "ao/bake/denoise.h"
#include "ao/bake/padding.h"
#include "ao/bake/texel_rays_internal.h"
#include "ao/core/error.h"
#include "ao/core/params_table.h"
#include "ao/core/sampling.h"
#include "ao/simd/sampling_internal.h"
#include "ao/reference/embree_scene_internal.h"
#include "ao/reference/mean_accumulator_internal.h"
#include "ao/reference/ray_offset.h"

namespace ao {

namespace {

constexpr int kMissFillRings = 64;
constexpr int kMaxCageSkips = 64;  // back faces a cage ray may pass through before it counts as a miss

using detail::PatchPiece;
using detail::TriangleNormals;

struct HighHit {
  bool hit = false;
  Vec3 p, n, ng;  // position, interpolated normal, face normal of the high mesh
};

// First front face of `targets` along o + t d, t in [0, tfar].
HighHit trace_cage_ray(const RayScene& targets, const TriangleNormals& fn, RTCIntersectContext& ctx, Vec3 o, Vec3 d, float tfar) {
  float tnear = 0.0f;
  for (int k = 0; k < kMaxCageSkips; ++k) {
    RTCRayHit rh{};
    rh.ray = {o.x, o.y, o.z, tnear, d.x, d.y, d.z, 0.0f, tfar, 0xffffffffu, 0, 0};
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(embree_scene(targets), &ctx, &rh);  // targets are triangles (high_to_low.h): (u, v) are barycentrics
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {};
    const HitRef hit = resolve(targets, rh.hit.geomID, rh.hit.instID[0], rh.hit.primID);
    const Affine3* nt = hit.normal_to_world;  // null: the mesh is in world space
    const Vec3 ng = nt ? normalize(nt->vector(fn.per_mesh[hit.mesh][hit.triangle])) : fn.per_mesh[hit.mesh][hit.triangle];
    if (dot(ng, d) < 0) {
      // Embree's barycentrics: u weights vertex 1, v vertex 2.
      const Mesh& m = targets.scene().meshes[hit.mesh];
      const std::uint32_t* i = &m.indices[3 * static_cast<std::size_t>(hit.triangle)];
      const float u = rh.hit.u, v = rh.hit.v, w = 1.0f - u - v;
      Vec3 p0, p1, p2;
      world_triangle(targets, hit, p0, p1, p2);
      const Vec3 p = p0 * w + p1 * u + p2 * v;
      Vec3 n0 = m.normals[i[0]], n1 = m.normals[i[1]], n2 = m.normals[i[2]];
      if (nt) n0 = normalize(nt->vector(n0)), n1 = normalize(nt->vector(n1)), n2 = normalize(nt->vector(n2));
      Vec3 n = normalize(n0 * w + n1 * u + n2 * v);
      if (!(length(n) > 0.5f)) n = ng;
      return {true, p, n, ng};
    }
    tnear = std::nextafter(rh.ray.tfar, kInfinity);  // a back face: the ray is inside the high mesh here
  }
  return {};
}

}  // namespace

std::vector<std::vector<Vec3>> smoothed_vertex_normals(const Scene& low) {
  std::map<std::array<float, 3>, Vec3> sum;
  for (const Mesh& m : low.meshes)
    for (std::size_t v = 0; v < m.positions.size(); ++v) {
      Vec3& s = sum[{m.positions[v].x, m.positions[v].y, m.positions[v].z}];
      s = s + m.normals[v];
    }
  std::vector<std::vector<Vec3>> out;
  for (const Mesh& m : low.meshes) {
    auto& o = out.emplace_back(m.positions.size());
    for (std::size_t v = 0; v < m.positions.size(); ++v) {
      const Vec3 s = sum[{m.positions[v].x, m.positions[v].y, m.positions[v].z}];
      o[v] = length(s) > 0 ? normalize(s) : m.normals[v];
    }
  }
  return out;
}

namespace {

// Where the AO rays of a point of the low patch leave: its cage ray, through the point, to the
// first front face of the high mesh.
struct CageRays {
  const Scene& low;
  const CagePositions& cage;
  const std::vector<std::vector<Vec3>>& smooth;  // smoothed_vertex_normals(low)
  const RayScene& targets;
  const TriangleNormals& target_fn;
  const HighToLowParams& params;
  float surface_eps;  // cage this close to the surface: no direction from it

  HighHit operator()(RTCIntersectContext& ctx, const detail::PatchSample& s) const {
    const PatchPiece& pc = *s.piece;
    const Vec3 p = s.position(), bary = s.barycentrics();
    const std::uint32_t* vi = &low.meshes[pc.mesh].indices[3 * pc.triangle];
    const auto& cg = cage[pc.mesh];
    const Vec3 c = cg[vi[0]] * bary.x + cg[vi[1]] * bary.y + cg[vi[2]] * bary.z;
    const float cage_distance = length(c - p);
    Vec3 d;
    if (cage_distance > surface_eps) {
      d = (p - c) / cage_distance;
    } else {
      const auto& sn = smooth[pc.mesh];
      d = -normalize(sn[vi[0]] * bary.x + sn[vi[1]] * bary.y + sn[vi[2]] * bary.z);
    }
    const float front = params.max_front.value_or(cage_distance), back = params.max_back.value_or(cage_distance);
    return trace_cage_ray(targets, target_fn, ctx, p - d * front, d, front + back);
  }
};

// A tile's worker for bake_high_to_low. A texel's P = min(cage_points, samples) cage points are
// its P points of a 2-D Owen-scrambled Sobol sequence (its TexelSampleSet for P points a texel,
// the key hashed once more) mapped onto the patch by area (sample_patch): stratified over the
// texel's patch. Cage point j carries the AO directions of samples [j n / P, (j + 1) n / P) of the
// texel's n samples (dimensions 0-1 of sobol_owen_4d, its TexelSampleSet, the single-mesh baker's
// direction dimensions): at n / P a power of two each block is a (0, m, 2)-net of its own,
// stratified over the hemisphere, and the blocks together are the texel's whole net.
// The directions of the texel's cage points go to Embree in packets filled with the rays of
// consecutive texels (PackedTracer: a cage point's share is a lane or two at a few rays a texel);
// the samples of a cage point that finds no high surface are left out.
template <int N>
class TexelWorker {
 public:
  TexelWorker(const CageRays& cage_rays, const detail::Tracer& tracer, const HighToLowParams& params, float offset, BakeResult& out,
              TexelGuides* guides, std::atomic<std::uint64_t>& rays)
      : cage_rays_(cage_rays), tracer_(tracer, true, params.ao.bent_normals), sums_(out, guides, params.ao.samples, params.ao.bent_normals, true), params_(params),
        offset_(offset), guides_(guides), rays_(rays), spread_(detail::cone_disk_radius(params.ao.spread_angle)) {}

  void operator()(RTCIntersectContext& ctx, int x, int y, std::size_t texel, const std::vector<PatchPiece>& patch, std::span<const TexelPiece>) {
    if (guides_) {
      const std::size_t slot = guides_->slot(x, y);
      detail::patch_guide(patch, false, guides_->position[slot], guides_->normal[slot]);
    }
    const int samples = params_.ao.samples, points = std::min(params_.cage_points, samples);
    // The directions and the cage points both from the texel's block's sequences (TexelSampleSet).
    const detail::TexelSampleSet set = detail::texel_sample_set(params_.ao.seed, x, y, samples);
    const detail::TexelSampleSet cage = detail::texel_sample_set(params_.ao.seed, x, y, points);
    const std::uint32_t point_key = hash_combine(cage.key, 0x3c6ef372u);
    const bool geometric = params_.ao.normal == SurfaceNormal::Geometric;
    block_first_ = -1;
    std::uint64_t traced = 0;
    for (int j = 0; j < points; ++j) {
      const HighHit h = cage_rays_(ctx, detail::sample_patch(patch, sobol_owen_2d(cage.first + static_cast<std::uint32_t>(j), point_key)));
      if (!h.hit) continue;
      // Inside (thickness): the high surface turned over, as the texel baker turns its patch.
      const float side = params_.ao.hemisphere == Hemisphere::Inside ? -1.0f : 1.0f;
      const Vec3 ng = h.ng * side, n = h.n * side;
      const Vec3 origin = h.p + ng * offset_;
      const int end = static_cast<int>(static_cast<std::int64_t>(j + 1) * samples / points);
      for (int first = static_cast<int>(static_cast<std::int64_t>(j) * samples / points); first < end; first += 16) {
        const int count = std::min(16, end - first);
        points_of(first, count, set);  // dimensions 0-1: the direction
        if (spread_ < 1.0f) detail::narrow_to_cone(u_, count, spread_, cone_u_);
        detail::make_hemisphere_rays(origin, geometric ? ng : n, ng, spread_ < 1.0f ? cone_u_ : u_, count, batch_);
        std::uint32_t strata[16];
        for (int k = 0; k < count; ++k) {
          strata[k] = sums_.stratum(u_[0][k], u_[1][k]);
          traced += batch_.valid[k] ? 1 : 0;
        }
        tracer_.add(ctx, batch_, count, strata, sums_);
      }
    }
    rays_ += static_cast<std::uint64_t>(points) + traced;  // a cage ray per cage point, and the AO rays
    tracer_.end_texel(static_cast<std::uint32_t>(texel), sums_);  // (texels fit in 32 bits: kMaxSize^2 = 2^28)
  }
  void finish(RTCIntersectContext& ctx) { tracer_.flush(ctx, sums_); }

 private:
  // Points first .. first + count - 1 of the texel's Sobol set into lanes 0 .. count - 1 of u_:
  // a cage point's few samples are copied from the aligned block of 16 the texel's points are made
  // in, so a texel scrambles each block once, not once per cage point.
  void points_of(int first, int count, const detail::TexelSampleSet& set) {
    int at = 0;
    while (at < count) {
      const int block = (first + at) / 16 * 16;
      if (block != block_first_) {
        sobol_owen_4d_batch(set.first + static_cast<std::uint32_t>(block), std::min(16, params_.ao.samples - block), set.key, block_u_);
        block_first_ = block;
      }
      const int from = first + at - block, n = std::min(count - at, 16 - from);
      for (int d = 0; d < 4; ++d) std::copy_n(&block_u_[d][from], n, &u_[d][at]);
      at += n;
    }
  }

  const CageRays& cage_rays_;
  detail::PackedTracer<N> tracer_;
  detail::TexelSums sums_;
  const HighToLowParams& params_;
  float offset_;
  TexelGuides* guides_;
  std::atomic<std::uint64_t>& rays_;
  float spread_;                     // the cone's disk radius, sin(spread_angle / 2)
  alignas(64) float u_[4][16] = {};  // lanes past a block's count keep any finite values
  alignas(64) float block_u_[4][16] = {};  // the texel's points block_first_ .. block_first_ + 15
  int block_first_ = -1;
  alignas(64) float cone_u_[4][16] = {};
  alignas(64) detail::TexelRayBatch batch_;
};

}  // namespace

const ParamTable<HighToLowParams>& high_to_low_param_table() {
  using P = Param<HighToLowParams>;
  using H = HighToLowParams;
  static const ParamTable<H> table{
      "bake high-to-low",
      {nested_params<H>(raytraced_bake_param_table(), &H::ao),
       {P::optional_real("cage_extrusion", &H::cage_extrusion, Range::closed(0, kMaxCoordinate), "world units",
                         "D: cage = low vertex + D x smoothed normal; null = fitted to the pair (rays reach the high mesh from ~99% of the low surface; 0.01 to 0.1 x the low diagonal); not with an explicit cage"),
        P::optional_real("max_front", &H::max_front, Range::closed(0, kMaxCoordinate), "world units",
                         "how far outside the low surface a ray starts; null = at the cage"),
        P::optional_real("max_back", &H::max_back, Range::closed(0, kMaxCoordinate), "world units",
                         "how far inside the low surface a ray still looks for the high mesh; null = the cage distance at that point"),
        P::integer("cage_points", &H::cage_points, Range::closed(1, 1 << 20), "",
                   "cage rays per texel, stratified over its patch, each carrying an equal share of the texel's AO rays (at most one per sample)")}}};
  return table;
}

void HighToLowParams::validate() const {
  high_to_low_param_table().validate(*this);
  ao.validate();
  if (ao.texel_sampling == TexelSampling::Centre) throw InputError("high-to-low: texel_sampling centre is for single-mesh maps; rays leave each texel's patch of the cage");
}
void to_json(nlohmann::json& j, const HighToLowParams& p) { j = high_to_low_param_table().to_json(p); }
void from_json(const nlohmann::json& j, HighToLowParams& p) { high_to_low_param_table().from_json(j, p); }

CagePositions extrude_cage(const Scene& low, float distance) {
  const auto normals = smoothed_vertex_normals(low);
  CagePositions cage;
  for (std::size_t mi = 0; mi < low.meshes.size(); ++mi) {
    const Mesh& m = low.meshes[mi];
    auto& c = cage.emplace_back(m.positions.size());
    for (std::size_t v = 0; v < m.positions.size(); ++v) c[v] = m.positions[v] + normals[mi][v] * distance;
  }
  return cage;
}

CagePositions cage_from_mesh(const Scene& low, const Scene& cage) {
  if (cage.meshes.size() != low.meshes.size())
    throw InputError(cage.name + ": the cage has " + std::to_string(cage.meshes.size()) + " meshes, the low mesh " + std::to_string(low.meshes.size()) +
                     " (a cage must have the low mesh's topology)");
  CagePositions out;
  for (std::size_t mi = 0; mi < low.meshes.size(); ++mi) {
    const Mesh& l = low.meshes[mi];
    const Mesh& c = cage.meshes[mi];
    if (c.positions.size() != l.positions.size() || c.indices != l.indices)
      throw InputError(cage.name + ": mesh " + std::to_string(mi) + " has " + std::to_string(c.positions.size()) + " vertices and " +
                       std::to_string(c.triangle_count()) + " triangles, the low mesh " + std::to_string(l.positions.size()) + " and " +
                       std::to_string(l.triangle_count()) + " (or the triangles differ): a cage must have the low mesh's topology");
    out.push_back(c.positions);
  }
  return out;
}

BakeResult bake_high_to_low(const Scene& low, const TexelCoverage& cov, const CagePositions& cage, const RayScene& targets, const RayScene& occluders,
                            const HighToLowParams& given, const ProgressFn& progress) {
  given.validate();
  HighToLowParams params = given;  // a relative distance is a fraction of the low mesh's size
  params.ao = given.ao.with_absolute_distance(baked_bounds(low));
  if (cage.size() != low.meshes.size()) throw InputError("high-to-low: the cage has a different number of meshes than the low scene");
  if (targets.quads()) throw InputError("high-to-low: the high meshes' BVH must hold triangles (built without BvhOptions::quads)");
  const Falloff falloff = params.ao.falloff();
  const TriangleNormals target_fn = detail::face_normals(targets.scene());
  const TriangleNormals occluder_fn = detail::face_normals(occluders.scene());
  const auto smooth = smoothed_vertex_normals(low);
  const detail::Tracer tracer{occluders, falloff, occluder_fn, params.ao.ignore_back_faces};
  const float offset = params.ao.offset > 0 ? params.ao.offset : ray_offset_distance(bounds_magnitude(occluders.bounds()));
  const int width = cov.width, height = cov.height;
  BakeResult out;
  out.visibility = Image<float>(width, height, 0.0f);
  out.mask = cov.mask;
  out.missed = Image<std::uint8_t>(width, height, std::uint8_t{0});
  out.covered_texels = cov.covered_texels;
  out.warnings = cov.warnings();
  if (params.ao.bent_normals) out.bent_normal = Image<Vec3>(width, height, Vec3{0, 0, 0});
  const float surface_eps = 1e-6f * occluders.bounds().diagonal();  // cage this close to the surface: no direction from it
  const CageRays cage_rays{low, cage, smooth, targets, target_fn, params, surface_eps};
  // The filter's guides are the low mesh's patches: the map lives in its UV charts.
  const bool denoise = params.ao.denoise > 0;
  TexelGuides guides;
  if (denoise) guides = TexelGuides(cov.mask);
  std::atomic<std::uint64_t> rays{0};
  const TriangleNormals low_fn = detail::face_normals(low);
  detail::for_each_texel_patch(occluders, low, cov, low_fn, progress, [&]<int N>() {
    return TexelWorker<N>(cage_rays, tracer, params, offset, out, denoise ? &guides : nullptr, rays);
  });
  out.rays = rays.load();
  for (std::size_t i = 0; i < out.missed.size(); ++i) out.missed_texels += out.missed[i];
  if (denoise) {  // over the texels that have a value; the missed ones are filled after, from filtered neighbours
    Image<std::uint8_t> valid = out.mask;
    for (std::size_t i = 0; i < valid.size(); ++i) valid[i] = valid[i] && !out.missed[i];
    denoise_map(out.visibility, valid, cov, guides, params.ao.denoise);
  }
  fill_missed_texels(out);
  out.stats = {{"rays", out.rays}, {"offset", offset}, {"missed_texels", out.missed_texels}};
  return out;
}

void fill_missed_texels(BakeResult& r) {
  if (r.missed_texels == 0 || r.missed.empty()) return;
  Image<std::uint8_t> ok(r.mask.width(), r.mask.height(), std::uint8_t{0});
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < ok.size(); ++i)
    if (r.mask[i] && !r.missed[i]) {
      ok[i] = 1;
      sum += r.visibility[i];
      ++count;
    }
  const float mean = count ? static_cast<float>(sum / static_cast<double>(count)) : 1.0f;
  const Image<std::int32_t> nearest = nearest_valid_texel(ok, kMissFillRings);
  for (std::size_t i = 0; i < ok.size(); ++i) {
    if (!r.missed[i]) continue;
    const std::int32_t s = nearest[i];
    r.visibility[i] = s >= 0 ? r.visibility[static_cast<std::size_t>(s)] : mean;
    if (!r.bent_normal.empty() && s >= 0) r.bent_normal[i] = r.bent_normal[static_cast<std::size_t>(s)];
  }
}

}  // namespace ao
