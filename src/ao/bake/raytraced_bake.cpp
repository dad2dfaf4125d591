// Inside-out baking of the per-texel AO of McGraw & Sowers' eq. 2 (and, with a distance R, of the
// obscurance integral the ground truth in reference/raytraced.h estimates):
//   V(T) = (1/A(T)) * integral over the texel's patch S of (1/pi) * integral over the hemisphere
//          of mu(D(x, w)) (w . n) dw dS.
// Both integrals are estimated together: sample i draws a point uniformly by area on the patch
// (texel_coverage.h gives the pieces of triangles in the texel with their world areas) and a
// cosine-weighted direction about the interpolated normal there (pdf cos/pi cancels the cosine and
// 1/pi), so V is the plain mean of mu over the samples. A point per ray, rather than one point at
// the texel centre, is what keeps thin charts and texels that straddle several triangles from
// aliasing. The patch sampling and the ray loop (reference/raytraced.cpp's, with an origin per lane,
// unlimited distance and back-face skipping) are in texel_rays.h, shared with high_to_low.cpp.
#include "ao/bake/raytraced_bake.h"

#include <array>
#include <cmath>

#include "ao/bake/texel_rays_internal.h"
#include "ao/core/error.h"
#include "ao/core/parallel.h"
#include "ao/core/sampling.h"
#include "ao/reference/packets_internal.h"
#include "ao/reference/ray_offset.h"

namespace ao {

namespace {

constexpr int kTile = 16;
constexpr int kMaxSamples = 1 << 20;

using detail::face_normals;
using detail::PatchPiece;
using detail::point_at_uv;
using detail::SurfacePoint;
using detail::Tracer;
using detail::TriangleNormals;

}  // namespace

void RaytracedBakeParams::validate() const {
  if (samples < 1 || samples > kMaxSamples) throw InputError("bake raytraced: samples must be in [1, 1048576], got " + std::to_string(samples));
  if (max_distance && !(*max_distance > 0 && std::isfinite(*max_distance)))
    throw InputError("bake raytraced: max distance must be a finite number > 0 (omit it for unlimited distance)");
  if (!(offset >= 0.0f && offset <= kMaxCoordinate)) throw InputError("bake raytraced: --offset must be a number in [0, 1e9] world units (kMaxCoordinate)");
  if (max_distance) falloff().validate();
}

Falloff RaytracedBakeParams::falloff() const {
  // Unlimited distance: mu(d) = 0 for every hit and 1 for a miss, a Step at R = +infinity. It is
  // built here, not validated: Falloff::validate rightly rejects an infinite R for the methods
  // whose kernels divide by it.
  if (!max_distance) return Falloff{Membership::Step, kInfinity};
  return Falloff{membership, *max_distance};
}

void to_json(nlohmann::json& j, const RaytracedBakeParams& p) {
  j = {{"samples", p.samples},
       {"max_distance", p.max_distance ? nlohmann::json(*p.max_distance) : nlohmann::json("unlimited")},
       {"membership", to_string(p.membership)},
       {"offset", p.offset},
       {"ignore_back_faces", p.ignore_back_faces},
       {"bent_normals", p.bent_normals},
       {"seed", p.seed}};
}

BakeResult bake_raytraced(const RayScene& rs, const TexelCoverage& cov, const RaytracedBakeParams& params, const ProgressFn& progress) {
  params.validate();
  const Scene& scene = rs.scene();
  const Falloff falloff = params.falloff();
  const TriangleNormals fn = face_normals(scene);
  const Tracer tracer{rs, falloff, fn, params.ignore_back_faces};
  const int w = cov.width, h = cov.height;
  BakeResult out;
  out.visibility = Image<float>(w, h, 0.0f);
  out.mask = cov.mask;
  out.covered_texels = cov.covered_texels;
  out.warnings = cov.warnings();
  if (params.bent_normals) out.bent_normal = Image<Vec3>(w, h, Vec3{0, 0, 0});
  ProgressCounter counter(progress, cov.texel_count());
  detail::dispatch_packet_width(rs.native_packet_width(), [&]<int N>() {
    parallel_for_tiles(w, h, kTile, [&](const Tile& t) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      std::vector<PatchPiece> patch;
      constexpr int batch = N == 1 ? 16 : N;
      std::array<Vec3, batch> org, dir;
      std::array<float, batch> mu;
      for (int y = t.y0; y < t.y1; ++y)
        for (int x = t.x0; x < t.x1; ++x) {
          const std::size_t texel = static_cast<std::size_t>(y) * w + x;
          if (!cov.mask[texel]) continue;
          detail::build_patch(scene, cov, texel, patch);
          if (patch.empty()) continue;
          const std::uint32_t key = pixel_seed(params.seed, x, y);
          const std::uint32_t key_point = hash_combine(key, 0x9017u), key_dir = hash_combine(key, 0xd1eu);
          double sum = 0;
          Vec3 bent{0, 0, 0};
          for (int first = 0; first < params.samples; first += batch) {
            const int count = std::min(batch, params.samples - first);
            int live = 0;
            for (int k = 0; k < count; ++k) {
              const auto i = static_cast<std::uint32_t>(first + k);
              // Point: uniform by area over the patch (texel_rays.h).
              const detail::PatchSample ps = detail::sample_patch(patch, sobol_owen_2d(i, key_point));
              const PatchPiece& pc = patch[ps.piece];
              const SurfacePoint sp = point_at_uv(scene, cov, pc.mesh, pc.triangle, ps.uv, fn);
              const Vec3 d = Frame::from_normal(sp.n).to_world(cosine_hemisphere(sobol_owen_2d(i, key_dir)));
              if (dot(d, sp.ng) <= 0) continue;  // below the face: occluded by the surface itself (mu = 0)
              // Off the triangle by the scale-free offset of ray_offset.h, or the user's fixed one.
              const float offset = params.offset > 0 ? params.offset : ray_offset_distance(triangle_magnitude(scene.meshes[pc.mesh], pc.triangle));
              org[static_cast<std::size_t>(live)] = sp.p + sp.ng * offset;
              dir[static_cast<std::size_t>(live)] = d;
              ++live;
            }
            tracer.template trace<N>(ctx, org.data(), dir.data(), live, mu.data());
            for (int k = 0; k < live; ++k) {
              sum += mu[static_cast<std::size_t>(k)];
              bent += dir[static_cast<std::size_t>(k)] * mu[static_cast<std::size_t>(k)];
            }
          }
          out.visibility[texel] = static_cast<float>(sum / params.samples);
          if (params.bent_normals) out.bent_normal[texel] = normalize(bent);
        }
      counter.add(static_cast<std::size_t>(t.x1 - t.x0) * (t.y1 - t.y0));
    });
  });
  out.rays = static_cast<std::uint64_t>(cov.covered_texels) * static_cast<std::uint64_t>(params.samples);
  out.stats = {{"rays", out.rays}, {"offset", params.offset > 0 ? nlohmann::json(params.offset) : nlohmann::json("scale-free")}};
  return out;
}

std::vector<float> bake_vertices_raytraced(const RayScene& rs, const RaytracedBakeParams& params, std::uint64_t* rays_traced,
                                           const ProgressFn& progress) {
  params.validate();
  const Scene& scene = rs.scene();
  const Falloff falloff = params.falloff();
  const TriangleNormals fn = face_normals(scene);
  const Tracer tracer{rs, falloff, fn, params.ignore_back_faces};
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
  ProgressCounter counter(progress, verts.size());
  detail::dispatch_packet_width(rs.native_packet_width(), [&]<int N>() {
    // One "row" of vertices, tiled 256 at a time.
    parallel_for_tiles(count, 1, 256, [&](const Tile& t) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      constexpr int batch = N == 1 ? 16 : N;
      std::array<Vec3, batch> org, dir;
      std::array<float, batch> mu;
      for (int vi = t.x0; vi < t.x1; ++vi) {
        const Mesh& m = scene.meshes[verts[static_cast<std::size_t>(vi)].first];
        const std::uint32_t v = verts[static_cast<std::size_t>(vi)].second;
        const Vec3 nrm = normalize(m.normals[v]);
        const Frame frame = Frame::from_normal(nrm);
        const std::uint32_t key = pixel_seed(params.seed, vi, 0);
        const float offset = mesh_offset[verts[static_cast<std::size_t>(vi)].first];
        double sum = 0;
        for (int first = 0; first < params.samples; first += batch) {
          const int c = std::min(batch, params.samples - first);
          for (int k = 0; k < c; ++k) {
            org[static_cast<std::size_t>(k)] = m.positions[v] + nrm * offset;
            dir[static_cast<std::size_t>(k)] = frame.to_world(cosine_hemisphere(sobol_owen_2d(static_cast<std::uint32_t>(first + k), key)));
          }
          tracer.template trace<N>(ctx, org.data(), dir.data(), c, mu.data());
          for (int k = 0; k < c; ++k) sum += mu[static_cast<std::size_t>(k)];
        }
        out[static_cast<std::size_t>(vi)] = static_cast<float>(sum / params.samples);
      }
      counter.add(static_cast<std::size_t>(t.x1 - t.x0));
    });
  });
  if (rays_traced) *rays_traced = static_cast<std::uint64_t>(verts.size()) * static_cast<std::uint64_t>(params.samples);
  return out;
}

}  // namespace ao
