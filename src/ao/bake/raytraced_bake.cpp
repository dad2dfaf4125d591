// SPDX-License-Identifier: Apache-2.0
// Inside-out baking of the per-texel AO of McGraw & Sowers' eq. 2 (and, with a distance R, of the
// obscurance integral the ground truth in reference/raytraced.h estimates):
//   V(T) = (1/A(T)) * integral over the texel's patch S of (1/pi) * integral over the hemisphere
//          of mu(D(x, w)) (w . n) dw dS.
// Both integrals are estimated together: sample i draws a point uniformly by area on the patch
// (texel_coverage.h gives the pieces of triangles in the texel with their world areas) and a
// cosine-weighted direction about the interpolated normal there (pdf cos/pi cancels the cosine and
// 1/pi), so V is the plain mean of mu over the samples. A point per ray, rather than one point at
// the texel centre, is what keeps thin charts and texels that straddle several triangles from
// aliasing. The patch (its pieces with world-space corners, built once per texel), the sample set
// in direction order (TexelPoints), the lane-parallel ray maker and the tracer (reference/
// raytraced.cpp's tracing, with an origin per lane, unlimited distance and back-face skipping) and
// the tile loop are in texel_rays_internal.h, shared with high_to_low.cpp; the rays of consecutive
// texels fill packets of 16 together (PackedTracer), which go to Embree as one occlusion packet
// where its native width is 16, else in packets of its width (BatchTracer).
#include "ao/bake/raytraced_bake.h"

#include <algorithm>
#include <array>
#include <span>
#include <cmath>
#include <cstdint>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "ao/bake/denoise.h"
#include "ao/bake/texel_rays_internal.h"
#include "ao/core/error.h"
#include "ao/core/params_table.h"
#include "ao/core/sampling.h"
#include "ao/reference/mean_accumulator_internal.h"
#include "ao/reference/ray_offset.h"
#include "ao/reference/ray_tiles_internal.h"

namespace ao {

namespace {

constexpr int kMaxSamples = 1 << 20;

using detail::face_normals;

// The triangles around each vertex of a mesh (CSR: those of vertex v are triangles[first[v] ..
// first[v + 1])) with their running area sum, for the geometric-normal per-vertex bake.
struct VertexFaces {
  std::vector<std::uint32_t> first, triangles;
  std::vector<float> cumulative_area;
};

std::vector<VertexFaces> vertex_faces(const Scene& scene) {
  std::vector<VertexFaces> out;
  for (const Mesh& m : scene.meshes) {
    VertexFaces& vf = out.emplace_back();
    vf.first.assign(m.positions.size() + 1, 0);
    for (const std::uint32_t i : m.indices) ++vf.first[i + 1];
    for (std::size_t v = 0; v < m.positions.size(); ++v) vf.first[v + 1] += vf.first[v];
    vf.triangles.resize(m.indices.size());
    vf.cumulative_area.resize(m.indices.size());
    std::vector<std::uint32_t> fill(vf.first.begin(), vf.first.end() - 1);
    for (std::size_t t = 0; t < m.triangle_count(); ++t)
      for (int c = 0; c < 3; ++c) vf.triangles[fill[m.indices[3 * t + c]]++] = static_cast<std::uint32_t>(t);
    for (std::size_t v = 0; v < m.positions.size(); ++v) {
      float sum = 0;
      for (std::uint32_t j = vf.first[v]; j < vf.first[v + 1]; ++j) {
        const std::uint32_t* i = &m.indices[3 * static_cast<std::size_t>(vf.triangles[j])];
        sum += 0.5f * length(cross(m.positions[i[1]] - m.positions[i[0]], m.positions[i[2]] - m.positions[i[0]]));
        vf.cumulative_area[j] = sum;
      }
    }
  }
  return out;
}
using detail::PatchPiece;
using detail::Tracer;
using detail::TriangleNormals;

// A tile's worker for bake_raytraced: the texel's sample points in direction order (TexelPoints),
// made into rays 16 at a time in SIMD lanes (make_texel_rays), and traced in packets filled with
// the rays of consecutive texels (PackedTracer), which hands each sample's mu back in order to
// the texel's sums (TexelSums).
template <int N>
class TexelWorker {
 public:
  /// `texels`: the map's coverage and the scene it was computed on, for texel_sampling centre.
  TexelWorker(const Tracer& tracer, const RaytracedBakeParams& params, BakeResult& out, TexelGuides* guides, const detail::TexelSource& texels)
      : tracer_(tracer, !params.bent_normals, params.bent_normals), sums_(out, guides, params.samples, params.bent_normals, false), params_(params), guides_(guides),
        texels_(texels), spread_(detail::cone_disk_radius(params.spread_angle)) {}

  void operator()(RTCIntersectContext& ctx, int x, int y, std::size_t texel, const std::vector<PatchPiece>& surface,
                  std::span<const TexelPiece> fragments) {
    const bool geometric = params_.normal == SurfaceNormal::Geometric;
    // Centre: the rays' patch is the single point under the texel's centre (the filter's guides
    // still describe the whole texel).
    const bool centre = params_.texel_sampling == TexelSampling::Centre;
    if (centre) detail::centre_patch(texels_, texel, fragments, surface, point_);
    const std::vector<PatchPiece>& sampled = centre ? point_ : surface;
    // Inside: the same patch with its normals turned over, so that the offset pushes the points
    // in and the directions leave below the surface.
    if (params_.hemisphere == Hemisphere::Inside) detail::turn_over(sampled, flipped_);
    const std::vector<PatchPiece>& patch = params_.hemisphere == Hemisphere::Inside ? flipped_ : sampled;
    table_.build(patch, params_.offset);
    if (guides_) {
      const std::size_t slot = guides_->slot(x, y);
      detail::patch_guide(surface, geometric, guides_->position[slot], guides_->normal[slot]);
    }
    points_.generate(detail::texel_sample_set(params_.seed, x, y, params_.samples), params_.samples);
    for (int first = 0; first < params_.samples; first += 16) {
      const int count = std::min(16, params_.samples - first);
      points_.lanes(first, count, u_);
      if (spread_ < 1.0f) detail::narrow_to_cone(u_, count, spread_, cone_u_);
      detail::make_texel_rays(patch, table_, spread_ < 1.0f ? cone_u_ : u_, count, geometric, batch_);
      std::uint32_t strata[16];
      for (int k = 0; k < count; ++k) strata[k] = sums_.stratum(u_[0][k], u_[1][k]);
      tracer_.add(ctx, batch_, count, strata, sums_);
    }
    // (Texels of the map fit in 32 bits: kMaxSize^2 = 2^28.)
    tracer_.end_texel(static_cast<std::uint32_t>(texel), sums_);
  }
  void finish(RTCIntersectContext& ctx) { tracer_.flush(ctx, sums_); }

 private:
  detail::PackedTracer<N> tracer_;
  detail::TexelSums sums_;
  const RaytracedBakeParams& params_;
  TexelGuides* guides_;
  const detail::TexelSource& texels_;
  detail::TexelPoints points_;
  float spread_;  // the cone's disk radius, sin(spread_angle / 2)
  std::vector<PatchPiece> point_, flipped_;
  alignas(64) detail::PatchTable table_;
  alignas(64) float u_[4][16];
  alignas(64) float cone_u_[4][16];
  alignas(64) detail::TexelRayBatch batch_;
};

}  // namespace

const ParamTable<RaytracedBakeParams>& raytraced_bake_param_table() {
  using P = Param<RaytracedBakeParams>;
  using R = RaytracedBakeParams;
  static const ParamTable<R> table{
      "bake raytraced",
      {P::integer("samples", &R::samples, Range::closed(1, kMaxSamples), "", "rays per texel (per vertex for per-vertex AO), each from its own point of the patch"),
       P::optional_real("max_distance", &R::max_distance, Range::above(0), "world units",
                        "R: occluders count only within this distance; null = unlimited (the paper's eq. 1)"),
       P::enumeration<Membership>("membership", &R::membership,
                                  {{"step", Membership::Step}, {"linear", Membership::Linear}, {"sqrt", Membership::Sqrt}, {"cubic", Membership::Cubic}},
                                  "falloff mu(d) within max_distance"),
       P::real("offset", &R::offset, Range::closed(0, kMaxCoordinate), "world units",
               "ray origin offset along the face normal; 0 = scale-free, a few float spacings of the coordinates (reference/ray_offset.h)"),
       P::boolean("ignore_back_faces", &R::ignore_back_faces, "rays pass through back faces (xNormal's and Substance's 'ignore backface')"),
       P::enumeration<SurfaceNormal>("normal", &R::normal, {{"shading", SurfaceNormal::Shading}, {"geometric", SurfaceNormal::Geometric}},
                                     "the hemisphere: about the interpolated shading normal, or the triangle's own"),
       P::boolean("bent_normals", &R::bent_normals, "also average the unoccluded directions per texel"),
       P::real("spread_angle", &R::spread_angle, Range::open_closed(0, 180), "degrees",
               "full angle of the cone of directions about the normal; 180 = the hemisphere"),
       P::boolean("relative_distance", &R::relative_distance, "max_distance is a fraction of the baked meshes' bounding-box diagonal"),
       P::enumeration<Hemisphere>("hemisphere", &R::hemisphere, {{"outside", Hemisphere::Outside}, {"inside", Hemisphere::Inside}},
                                  "outside: AO; inside: rays into the mesh, with a distance a thickness map"),
       P::enumeration<TexelSampling>("texel_sampling", &R::texel_sampling, {{"area", TexelSampling::Area}, {"centre", TexelSampling::Centre}},
                                     "maps: rays from points spread over each texel's surface (its mean V) or all from the point under its centre (point sampling, as Cycles)"),
       P::seed("seed", &R::seed, "keys the sample sets (one sequence per 4 x 4 block of texels; per vertex)"),
       P::real("denoise", &R::denoise, Range::closed(0, kMaxDenoiseSigma), "texels",
               "sigma of the texture-space filter of maps (denoise.h); 0 = off, the plain estimate of eq. 2")}};
  return table;
}

void RaytracedBakeParams::validate() const {
  raytraced_bake_param_table().validate(*this);
  if (relative_distance && !max_distance) throw InputError("bake raytraced: relative_distance needs max_distance (the fraction of the bounding-box diagonal)");
  if (hemisphere == Hemisphere::Inside && ignore_back_faces)
    throw InputError("bake raytraced: ignore_back_faces is for the outside hemisphere (inside the mesh, every hit is a back face)");
  if (max_distance && !relative_distance) falloff().validate();
}

RaytracedBakeParams RaytracedBakeParams::with_absolute_distance(const Bounds3& baked) const {
  if (!relative_distance || !max_distance) return *this;
  RaytracedBakeParams p = *this;
  const float diagonal = baked.empty() ? 0.0f : length(baked.extent());
  if (!(diagonal > 0)) throw InputError("bake raytraced: relative_distance needs baked meshes of non-zero size");
  p.max_distance = *max_distance * diagonal;
  p.relative_distance = false;
  p.validate();
  return p;
}

Bounds3 baked_bounds(const Scene& scene) {
  Bounds3 b;
  for (const Mesh& m : scene.meshes)
    if (!m.uvs.empty()) b.extend(m.bounds());
  return b.empty() ? scene.bounds() : b;  // no UVs: a per-vertex bake bakes every mesh
}

Falloff RaytracedBakeParams::falloff() const {
  // Unlimited distance: mu(d) = 0 for every hit and 1 for a miss, a Step at R = +infinity. It is
  // built here, not validated: Falloff::validate rightly rejects an infinite R for the methods
  // whose kernels divide by it.
  if (!max_distance) return Falloff{Membership::Step, kInfinity};
  return Falloff{membership, *max_distance};
}

void to_json(nlohmann::json& j, const RaytracedBakeParams& p) { j = raytraced_bake_param_table().to_json(p); }
void from_json(const nlohmann::json& j, RaytracedBakeParams& p) { raytraced_bake_param_table().from_json(j, p); }

BakeResult bake_raytraced(const RayScene& rs, const TexelCoverage& cov, const RaytracedBakeParams& given, const ProgressFn& progress) {
  given.validate();
  const Scene& scene = rs.scene();
  const RaytracedBakeParams params = given.with_absolute_distance(baked_bounds(scene));
  const Falloff falloff = params.falloff();
  const TriangleNormals fn = face_normals(scene);
  const Tracer tracer{rs, falloff, fn, params.ignore_back_faces};
  BakeResult out;
  out.visibility = Image<float>(cov.width, cov.height, 0.0f);
  out.mask = cov.mask;
  out.covered_texels = cov.covered_texels;
  out.warnings = cov.warnings();
  if (params.bent_normals) out.bent_normal = Image<Vec3>(cov.width, cov.height, Vec3{0, 0, 0});
  // The filter's guides, filled in the tile loop from the patches it builds anyway and each
  // texel's samples.
  const bool denoise = params.denoise > 0;
  TexelGuides guides;
  if (denoise) guides = TexelGuides(cov.mask);
  const detail::TexelSource texels{scene, cov, fn};
  detail::for_each_texel_patch(rs, scene, cov, fn, progress, [&]<int N>() {
    return TexelWorker<N>(tracer, params, out, denoise ? &guides : nullptr, texels);
  });
  if (denoise) denoise_map(out.visibility, cov.mask, cov, guides, params.denoise);
  out.rays = static_cast<std::uint64_t>(cov.covered_texels) * static_cast<std::uint64_t>(params.samples);
  out.stats = {{"rays", out.rays}, {"offset", params.offset > 0 ? nlohmann::json(params.offset) : nlohmann::json("scale-free")}};
  return out;
}

namespace {

/// 10 bits of x spread to every third bit (bits 0, 3, ..., 27).
std::uint32_t spread_bits(std::uint32_t x) {
  x &= 0x3ffu;
  x = (x | (x << 16)) & 0x030000ffu;
  x = (x | (x << 8)) & 0x0300f00fu;
  x = (x | (x << 4)) & 0x030c30c3u;
  x = (x | (x << 2)) & 0x09249249u;
  return x;
}

/// Indices into `verts` sorted by the 30-bit Morton code of the vertex positions in the scene's
/// bounds (ties keep index order, so the order is deterministic).
std::vector<std::uint32_t> morton_order(const Scene& scene, const std::vector<std::pair<std::uint32_t, std::uint32_t>>& verts) {
  const Bounds3 b = scene.bounds();
  const Vec3 extent = b.extent();
  const float side = std::max({extent.x, extent.y, extent.z, 1e-30f});
  std::vector<std::uint64_t> keyed(verts.size());  // code << 32 | index
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, verts.size(), 1 << 14), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i < r.end(); ++i) {
      const Vec3 p = (scene.meshes[verts[i].first].positions[verts[i].second] - b.lo) / side;
      const auto cell = [](float c) { return static_cast<std::uint32_t>(std::clamp(c * 1024.0f, 0.0f, 1023.0f)); };
      const std::uint32_t code = spread_bits(cell(p.x)) | (spread_bits(cell(p.y)) << 1) | (spread_bits(cell(p.z)) << 2);
      keyed[i] = (static_cast<std::uint64_t>(code) << 32) | i;
    }
  });
  tbb::parallel_sort(keyed.begin(), keyed.end());
  std::vector<std::uint32_t> order(verts.size());
  for (std::size_t i = 0; i < verts.size(); ++i) order[i] = static_cast<std::uint32_t>(keyed[i]);
  return order;
}

}  // namespace

std::vector<float> bake_vertices_raytraced(const RayScene& rs, const RaytracedBakeParams& given, std::uint64_t* rays_traced,
                                           const ProgressFn& progress) {
  given.validate();
  const Scene& scene = rs.scene();
  if (given.hemisphere == Hemisphere::Inside) throw InputError("bake raytraced: per-vertex bakes take the outside hemisphere (AO)");
  if (given.texel_sampling == TexelSampling::Centre) throw InputError("bake raytraced: texel_sampling centre is for maps (a vertex has no texel)");
  const RaytracedBakeParams params = given.with_absolute_distance(baked_bounds(scene));
  const float spread = detail::cone_disk_radius(params.spread_angle);
  require_no_instances(scene);
  const Falloff falloff = params.falloff();
  const TriangleNormals fn = face_normals(scene);
  const Tracer tracer{rs, falloff, fn, params.ignore_back_faces};
  const bool geometric = params.normal == SurfaceNormal::Geometric;
  const std::vector<VertexFaces> faces = geometric ? vertex_faces(scene) : std::vector<VertexFaces>{};
  std::vector<float> mesh_offset;  // a vertex has no single triangle: the offset scale is its mesh's largest coordinate
  for (const Mesh& m : scene.meshes) {
    const Bounds3 b = m.bounds();
    mesh_offset.push_back(params.offset > 0 ? params.offset : ray_offset_distance(std::max(max_abs_coordinate(b.lo), max_abs_coordinate(b.hi))));
  }
  std::vector<std::pair<std::uint32_t, std::uint32_t>> verts;  // (mesh, vertex)
  for (std::size_t m = 0; m < scene.meshes.size(); ++m)
    for (std::size_t v = 0; v < scene.meshes[m].positions.size(); ++v) verts.emplace_back(static_cast<std::uint32_t>(m), static_cast<std::uint32_t>(v));
  std::vector<float> out(verts.size(), 1.0f);
  const int count = static_cast<int>(verts.size());
  // Vertices are traced in Morton order of their positions, so consecutive vertices (one tile, one
  // thread) are close in space and reuse the BVH nodes and triangles in cache; a file's own vertex
  // order can jump across the model. The sample set and the output slot stay keyed by the vertex's
  // index, so the result is the same in any order.
  const std::vector<std::uint32_t> order = morton_order(scene, verts);
  ProgressCounter counter(progress, verts.size());
  // One "row" of vertices, tiled 256 at a time.
  detail::for_each_ray_tile(rs, count, 1, detail::RayTiling{256, 1}, counter, [&]<int N>(RTCIntersectContext& ctx, const Tile& t) {
    constexpr int batch = N == 1 ? 16 : N;
    std::array<Vec3, batch> org, dir;
    std::array<float, batch> mu;
    for (int oi = t.x0; oi < t.x1; ++oi) {
      const auto vi = static_cast<int>(order[static_cast<std::size_t>(oi)]);
      const Mesh& m = scene.meshes[verts[static_cast<std::size_t>(vi)].first];
      const std::uint32_t v = verts[static_cast<std::size_t>(vi)].second;
      const std::uint32_t mi = verts[static_cast<std::size_t>(vi)].first;
      const Vec3 nrm = normalize(m.normals[v]);
      const Frame frame = Frame::from_normal(nrm);
      const std::uint32_t key = pixel_seed(params.seed, vi, 0);
      const float offset = mesh_offset[mi];
      // Geometric: sample k takes the face whose share of the vertex's cumulative triangle area
      // contains (k + 0.5) / samples (stratified by area), and its direction about that face.
      std::span<const std::uint32_t> tris;
      std::span<const float> cdf;
      if (geometric) {
        const VertexFaces& vf = faces[mi];
        tris = std::span(vf.triangles).subspan(vf.first[v], vf.first[v + 1] - vf.first[v]);
        cdf = std::span(vf.cumulative_area).subspan(vf.first[v], vf.first[v + 1] - vf.first[v]);
      }
      detail::MeanAccumulator acc;
      for (int first = 0; first < params.samples; first += batch) {
        const int c = std::min(batch, params.samples - first);
        for (int k = 0; k < c; ++k) {
          Frame f = frame;
          if (!tris.empty()) {
            const float target = (static_cast<float>(first + k) + 0.5f) / static_cast<float>(params.samples) * cdf.back();
            const std::size_t j = std::min<std::size_t>(std::upper_bound(cdf.begin(), cdf.end(), target) - cdf.begin(), tris.size() - 1);
            f = Frame::from_normal(fn.per_mesh[mi][tris[j]]);
          }
          // Off along the vertex normal in both modes: it leans away from every face at the
          // vertex, so the origin clears all of them (a face normal would leave it on the plane
          // of a neighbouring face in a crease).
          org[static_cast<std::size_t>(k)] = m.positions[v] + nrm * offset;
          const Vec2 u = sobol_owen_2d(static_cast<std::uint32_t>(first + k), key);
          dir[static_cast<std::size_t>(k)] = f.to_world(cosine_hemisphere(spread < 1.0f ? detail::narrow_to_cone(u, spread) : u));
        }
        tracer.template trace<N>(ctx, org.data(), dir.data(), c, mu.data());
        for (int k = 0; k < c; ++k) acc.add(mu[static_cast<std::size_t>(k)]);
      }
      out[static_cast<std::size_t>(vi)] = static_cast<float>(acc.mean());
    }
    return static_cast<std::size_t>(t.x1 - t.x0);
  });
  if (rays_traced) *rays_traced = static_cast<std::uint64_t>(verts.size()) * static_cast<std::uint64_t>(params.samples);
  return out;
}

}  // namespace ao
