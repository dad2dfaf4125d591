// Inside-out baking of the per-texel AO of McGraw & Sowers' eq. 2 (and, with a distance R, of the
// obscurance integral the ground truth in reference/raytraced.h estimates):
//   V(T) = (1/A(T)) * integral over the texel's patch S of (1/pi) * integral over the hemisphere
//          of mu(D(x, w)) (w . n) dw dS.
// Both integrals are estimated together: sample i draws a point uniformly by area on the patch
// (texel_coverage.h gives the pieces of triangles in the texel with their world areas) and a
// cosine-weighted direction about the interpolated normal there (pdf cos/pi cancels the cosine and
// 1/pi), so V is the plain mean of mu over the samples. A point per ray, rather than one point at
// the texel centre, is what keeps thin charts and texels that straddle several triangles from
// aliasing. The ray loop is reference/raytraced.cpp's, with an origin per lane; it is repeated
// here rather than shared because it adds per-lane origins, unlimited distance and back-face skipping.
#include "ao/bake/raytraced_bake.h"

#include <array>
#include <cmath>

#include "ao/core/error.h"
#include "ao/core/parallel.h"
#include "ao/core/sampling.h"
#include "ao/reference/packets.h"
#include "ao/reference/ray_offset.h"

namespace ao {

namespace {

constexpr int kTile = 16;
constexpr int kMaxSamples = 1 << 20;
constexpr int kMaxBackFaceSkips = 64;  // a ray crossing more back faces than this counts as occluded

struct TriangleNormals {
  std::vector<std::vector<Vec3>> per_mesh;  // geometric (face) normal per triangle
};

TriangleNormals face_normals(const Scene& s) {
  TriangleNormals fn;
  for (const Mesh& m : s.meshes) {
    auto& v = fn.per_mesh.emplace_back(m.triangle_count());
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      const std::uint32_t* i = &m.indices[3 * t];
      v[t] = normalize(cross(m.positions[i[1]] - m.positions[i[0]], m.positions[i[2]] - m.positions[i[0]]));
    }
  }
  return fn;
}

struct Tracer {
  const RayScene& rs;
  const Falloff& falloff;
  const TriangleNormals& normals;
  bool ignore_back;

  // mu for one ray traced on its own (used to continue through back faces).
  float trace1(RTCIntersectContext& ctx, Vec3 o, Vec3 d, float tnear) const {
    const float reach = falloff.reach();
    for (int k = 0; k < kMaxBackFaceSkips; ++k) {
      RTCRayHit rh{};
      rh.ray = {o.x, o.y, o.z, tnear, d.x, d.y, d.z, 0.0f, reach, 0xffffffffu, 0, 0};
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(embree_scene(rs), &ctx, &rh);
      if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return 1.0f;
      if (!ignore_back || dot(normals.per_mesh[rh.hit.geomID][rh.hit.primID], d) <= 0) return falloff.mu(rh.ray.tfar);
      tnear = std::nextafter(rh.ray.tfar, kInfinity);  // a back face: look beyond it
    }
    return 0.0f;
  }

  // mu for `count` <= N rays with their own origins.
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
      alignas(64) typename detail::Packet<N>::RayHit rh;
      alignas(64) std::array<int, N> valid;
      for (int k = 0; k < N; ++k) {
        const int s = k < count ? k : 0;
        valid[k] = k < count ? -1 : 0;
        detail::set_ray_hit(rh, k, org[s], dir[s], reach);
      }
      if (occlusion_only) {
        detail::Packet<N>::occluded(valid.data(), embree_scene(rs), &ctx, &rh.ray);
        for (int k = 0; k < count; ++k) mu[k] = rh.ray.tfar[k] < 0 ? 0.0f : 1.0f;
      } else {
        detail::Packet<N>::intersect(valid.data(), embree_scene(rs), &ctx, &rh);
        for (int k = 0; k < count; ++k) {
          if (rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) {
            mu[k] = 1.0f;
          } else if (ignore_back && dot(normals.per_mesh[rh.hit.geomID[k]][rh.hit.primID[k]], dir[k]) > 0) {
            mu[k] = trace1(ctx, org[k], dir[k], std::nextafter(rh.ray.tfar[k], kInfinity));
          } else {
            mu[k] = falloff.mu(rh.ray.tfar[k]);
          }
        }
      }
    }
  }
};

// A texel's patch as sub-triangles in texel-unit UV space, each with the mesh triangle it lies on
// and its world area, for sampling points uniformly by area.
struct PatchPiece {
  std::uint32_t mesh, triangle;
  Vec2 a, b, c;
  double cdf;  // cumulative world area up to and including this piece
};

void build_patch(const Scene& s, const TexelCoverage& cov, std::size_t texel, std::vector<PatchPiece>& out) {
  out.clear();
  const int x = static_cast<int>(texel % cov.size), y = static_cast<int>(texel / cov.size);
  double acc = 0;
  for (std::uint32_t f = cov.offsets[texel]; f < cov.offsets[texel + 1]; ++f) {
    const TexelFragment& fr = cov.fragments[f];
    const Mesh& m = s.meshes[fr.mesh];
    const std::uint32_t* i = &m.indices[3 * fr.triangle];
    const ClipPolygon poly = clip_to_texel(texel_uv(m, i[0], cov.size), texel_uv(m, i[1], cov.size), texel_uv(m, i[2], cov.size), x, y);
    const double stretch = fr.uv_area > 0 ? fr.world_area / fr.uv_area : 0.0;
    for (int k = 1; k + 1 < poly.n; ++k) {  // fan of the convex clipped polygon
      const Vec2 a = poly.p[0], b = poly.p[k], c = poly.p[k + 1];
      const double area = 0.5 * std::abs((static_cast<double>(b.x) - a.x) * (c.y - a.y) - (static_cast<double>(c.x) - a.x) * (b.y - a.y));
      if (!(area > 0)) continue;
      acc += area * stretch;
      out.push_back({fr.mesh, fr.triangle, a, b, c, acc});
    }
  }
}

struct SurfacePoint {
  Vec3 p, n, ng;
};

// Point of mesh triangle `tri` at texel-unit UV `q` (barycentrics solved in UV space).
SurfacePoint point_at_uv(const Scene& s, const TexelCoverage& cov, std::uint32_t mesh, std::uint32_t tri, Vec2 q, const TriangleNormals& fn) {
  const Mesh& m = s.meshes[mesh];
  const std::uint32_t* i = &m.indices[3 * tri];
  const Vec2 a = texel_uv(m, i[0], cov.size), b = texel_uv(m, i[1], cov.size), c = texel_uv(m, i[2], cov.size);
  const float det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
  float l1 = ((q.x - a.x) * (c.y - a.y) - (c.x - a.x) * (q.y - a.y)) / det;
  float l2 = ((b.x - a.x) * (q.y - a.y) - (q.x - a.x) * (b.y - a.y)) / det;
  l1 = std::clamp(l1, 0.0f, 1.0f);
  l2 = std::clamp(l2, 0.0f, 1.0f - l1);
  const float l0 = 1.0f - l1 - l2;
  const Vec3 p = m.positions[i[0]] * l0 + m.positions[i[1]] * l1 + m.positions[i[2]] * l2;
  Vec3 n = normalize(m.normals[i[0]] * l0 + m.normals[i[1]] * l1 + m.normals[i[2]] * l2);
  const Vec3 ng = fn.per_mesh[mesh][tri];
  if (!(length(n) > 0.5f)) n = ng;
  return {p, n, ng};
}

}  // namespace

void RaytracedBakeParams::validate() const {
  if (samples < 1 || samples > kMaxSamples) throw InputError("bake raytraced: samples must be in [1, 1048576], got " + std::to_string(samples));
  if (max_distance && !(*max_distance > 0 && std::isfinite(*max_distance)))
    throw InputError("bake raytraced: max distance must be a finite number > 0 (omit it for unlimited distance)");
  if (!(offset >= 0.0f) || !std::isfinite(offset)) throw InputError("bake raytraced: offset must be a finite number >= 0");
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
  const int n = cov.size;
  BakeResult out;
  out.visibility = Image<float>(n, n, 0.0f);
  out.mask = cov.mask;
  out.covered_texels = cov.covered_texels;
  out.warnings = cov.warnings();
  if (params.bent_normals) out.bent_normal = Image<Vec3>(n, n, Vec3{0, 0, 0});
  ProgressCounter counter(progress, static_cast<std::size_t>(n) * n);
  detail::dispatch_packet_width(rs.native_packet_width(), [&]<int N>() {
    parallel_for_tiles(n, n, kTile, [&](const Tile& t) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      std::vector<PatchPiece> patch;
      constexpr int batch = N == 1 ? 16 : N;
      std::array<Vec3, batch> org, dir;
      std::array<float, batch> mu;
      for (int y = t.y0; y < t.y1; ++y)
        for (int x = t.x0; x < t.x1; ++x) {
          const std::size_t texel = static_cast<std::size_t>(y) * n + x;
          if (!cov.mask[texel]) continue;
          build_patch(scene, cov, texel, patch);
          if (patch.empty()) continue;
          const std::uint32_t key = pixel_seed(params.seed, x, y);
          const std::uint32_t key_point = hash_combine(key, 0x9017u), key_dir = hash_combine(key, 0xd1eu);
          const double total = patch.back().cdf;
          double sum = 0;
          Vec3 bent{0, 0, 0};
          for (int first = 0; first < params.samples; first += batch) {
            const int count = std::min(batch, params.samples - first);
            int live = 0;
            for (int k = 0; k < count; ++k) {
              const auto i = static_cast<std::uint32_t>(first + k);
              // Point: choose a piece by world area, then a uniform point in it (the piece index is
              // taken from u.x and u.x rescaled within the piece, which keeps the stratification).
              const Vec2 u = sobol_owen_2d(i, key_point);
              const double target = u.x * total;
              std::size_t pi = 0;
              while (pi + 1 < patch.size() && patch[pi].cdf <= target) ++pi;
              const double lo = pi == 0 ? 0.0 : patch[pi - 1].cdf;
              const float su = static_cast<float>(std::clamp((target - lo) / std::max(patch[pi].cdf - lo, 1e-300), 0.0, 1.0));
              const float r = std::sqrt(su);
              const PatchPiece& pc = patch[pi];
              const Vec2 q{pc.a.x * (1 - r) + r * ((1 - u.y) * pc.b.x + u.y * pc.c.x), pc.a.y * (1 - r) + r * ((1 - u.y) * pc.b.y + u.y * pc.c.y)};
              const SurfacePoint sp = point_at_uv(scene, cov, pc.mesh, pc.triangle, q, fn);
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
