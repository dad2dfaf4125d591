// Patch sampling for the inside-out bakers: see texel_rays.h.
#include "ao/bake/texel_rays_internal.h"

#include <algorithm>

namespace ao::detail {

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

void build_patch(const Scene& s, const TexelCoverage& cov, std::size_t texel, std::vector<PatchPiece>& out) {
  out.clear();
  const int x = static_cast<int>(texel % static_cast<std::size_t>(cov.width)), y = static_cast<int>(texel / static_cast<std::size_t>(cov.width));
  double acc = 0;
  for (std::uint32_t f = cov.offsets[texel]; f < cov.offsets[texel + 1]; ++f) {
    const TexelFragment& fr = cov.fragments[f];
    const Mesh& m = s.meshes[fr.mesh];
    const std::uint32_t* i = &m.indices[3 * fr.triangle];
    const ClipPolygon poly = clip_to_texel(texel_uv(m, i[0], cov.width, cov.height), texel_uv(m, i[1], cov.width, cov.height),
                                            texel_uv(m, i[2], cov.width, cov.height), x, y);
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

PatchSample sample_patch(const std::vector<PatchPiece>& patch, Vec2 u) {
  const double total = patch.back().cdf;
  const double target = u.x * total;
  std::size_t pi = 0;
  while (pi + 1 < patch.size() && patch[pi].cdf <= target) ++pi;
  const double lo = pi == 0 ? 0.0 : patch[pi - 1].cdf;
  const float su = static_cast<float>(std::clamp((target - lo) / std::max(patch[pi].cdf - lo, 1e-300), 0.0, 1.0));
  // Uniform point of triangle a b c: a + sqrt(s) ((1 - t)(b - a) + t (c - a)).
  const float r = std::sqrt(su);
  const PatchPiece& pc = patch[pi];
  return {pi, {pc.a.x * (1 - r) + r * ((1 - u.y) * pc.b.x + u.y * pc.c.x), pc.a.y * (1 - r) + r * ((1 - u.y) * pc.b.y + u.y * pc.c.y)}};
}

SurfacePoint point_at_uv(const Scene& s, const TexelCoverage& cov, std::uint32_t mesh, std::uint32_t tri, Vec2 q, const TriangleNormals& fn) {
  const Mesh& m = s.meshes[mesh];
  const std::uint32_t* i = &m.indices[3 * tri];
  const Vec2 a = texel_uv(m, i[0], cov.width, cov.height), b = texel_uv(m, i[1], cov.width, cov.height), c = texel_uv(m, i[2], cov.width, cov.height);
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
  return {p, n, ng, {l0, l1, l2}};
}

}  // namespace ao::detail
