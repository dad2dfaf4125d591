// Patch sampling for the inside-out bakers: see texel_rays_internal.h.
#include "ao/bake/texel_rays_internal.h"

#include <algorithm>

#include "ao/reference/ray_offset.h"

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

void build_patch(const Scene& s, const TexelCoverage& cov, const TriangleNormals& fn, std::size_t texel, std::vector<PatchPiece>& out) {
  out.clear();
  const int x = static_cast<int>(texel % static_cast<std::size_t>(cov.width)), y = static_cast<int>(texel / static_cast<std::size_t>(cov.width));
  double acc = 0;
  for (std::uint32_t f = cov.offsets[texel]; f < cov.offsets[texel + 1]; ++f) {
    const TexelFragment& fr = cov.fragments[f];
    const Mesh& m = s.meshes[fr.mesh];
    const std::uint32_t* i = &m.indices[3 * fr.triangle];
    const Vec2 a = texel_uv(m, i[0], cov.width, cov.height), b = texel_uv(m, i[1], cov.width, cov.height), c = texel_uv(m, i[2], cov.width, cov.height);
    const ClipPolygon poly = clip_to_texel(a, b, c, x, y);
    const double stretch = fr.uv_area > 0 ? fr.world_area / fr.uv_area : 0.0;
    // Barycentrics of each polygon corner, solved once in UV space and clamped to the triangle
    // (clipping rounds corners onto, or a hair past, its edges).
    const float det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    std::array<Vec3, 9> bary;
    for (int k = 0; k < poly.n; ++k) {
      const Vec2 q = poly.p[k];
      float l1 = ((q.x - a.x) * (c.y - a.y) - (c.x - a.x) * (q.y - a.y)) / det;
      float l2 = ((b.x - a.x) * (q.y - a.y) - (q.x - a.x) * (b.y - a.y)) / det;
      l1 = std::clamp(l1, 0.0f, 1.0f);
      l2 = std::clamp(l2, 0.0f, 1.0f - l1);
      bary[static_cast<std::size_t>(k)] = {1.0f - l1 - l2, l1, l2};
    }
    const float offset = ray_offset_distance(triangle_magnitude(m, fr.triangle));
    auto corner = [&](int k, PatchPiece& pc, int slot) {
      const Vec3 l = bary[static_cast<std::size_t>(k)];
      pc.bary[static_cast<std::size_t>(slot)] = l;
      pc.p[static_cast<std::size_t>(slot)] = m.positions[i[0]] * l.x + m.positions[i[1]] * l.y + m.positions[i[2]] * l.z;
      pc.n[static_cast<std::size_t>(slot)] = m.normals[i[0]] * l.x + m.normals[i[1]] * l.y + m.normals[i[2]] * l.z;
    };
    for (int k = 1; k + 1 < poly.n; ++k) {  // fan of the convex clipped polygon
      const Vec2 p0 = poly.p[0], p1 = poly.p[k], p2 = poly.p[k + 1];
      const double area = 0.5 * std::abs((static_cast<double>(p1.x) - p0.x) * (p2.y - p0.y) - (static_cast<double>(p2.x) - p0.x) * (p1.y - p0.y));
      if (!(area > 0)) continue;
      acc += area * stretch;
      PatchPiece& pc = out.emplace_back();
      pc.mesh = fr.mesh;
      pc.triangle = fr.triangle;
      corner(0, pc, 0);
      corner(k, pc, 1);
      corner(k + 1, pc, 2);
      pc.ng = fn.per_mesh[fr.mesh][fr.triangle];
      pc.offset = offset;
      pc.cdf = static_cast<float>(acc);
    }
  }
}

}  // namespace ao::detail
