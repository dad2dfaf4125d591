// SPDX-License-Identifier: Apache-2.0
// MikkTSpace tangent frames (Mikkelsen 2008) and the tangent space of a texel; see tangents.h.
#include "ao/bake/tangents.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <span>
#include <unordered_map>

#include "ao/core/error.h"

namespace ao {

namespace {

// Disjoint sets over the corners (union by index, path halving): the tangent groups.
struct CornerSets {
  std::vector<std::uint32_t> parent;
  explicit CornerSets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  void join(std::uint32_t a, std::uint32_t b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

// v without its component along the unit n, normalised (zero stays zero).
Vec3 in_plane(Vec3 v, Vec3 n) { return normalize(v - n * dot(n, v)); }

// Any unit vector perpendicular to the unit n.
Vec3 perpendicular(Vec3 n) { return Frame::from_normal(n).t; }

}  // namespace

std::vector<CornerTangent> mikktspace_tangents(const Mesh& m) {
  if (m.uvs.empty() || m.normals.size() != m.positions.size())
    throw InputError(m.name + ": tangents need the mesh's UVs and vertex normals");
  const std::size_t tris = m.triangle_count();
  // Per triangle: the direction of increasing u in its plane, unit, its sign flipped when the UV
  // triangle is mirrored (so that, with the bitangent sign, the frame is right-handed in UV), and
  // whether the UV triangle keeps the orientation (its signed UV area > 0).
  std::vector<Vec3> face_t(tris);
  std::vector<std::uint8_t> keeps(tris), degenerate(tris);
  for (std::size_t f = 0; f < tris; ++f) {
    const std::uint32_t* i = &m.indices[3 * f];
    const Vec3 d1 = m.positions[i[1]] - m.positions[i[0]], d2 = m.positions[i[2]] - m.positions[i[0]];
    const Vec2 a = m.uvs[i[0]], b = m.uvs[i[1]], c = m.uvs[i[2]];
    const float s1 = b.x - a.x, t1 = b.y - a.y, s2 = c.x - a.x, t2 = c.y - a.y;
    const float signed_area = s1 * t2 - t1 * s2;  // twice the UV triangle's signed area
    keeps[f] = signed_area > 0;
    // dP/du up to the positive factor 1 / signed_area: (t2 d1 - t1 d2); its sign follows the orientation.
    const Vec3 os = d1 * t2 - d2 * t1;
    degenerate[f] = !(std::abs(signed_area) > 0) || !(length(os) > 0);
    face_t[f] = degenerate[f] ? Vec3{0, 0, 0} : normalize(os) * (keeps[f] ? 1.0f : -1.0f);
  }
  // Corners at one vertex join when their triangles share an edge through that vertex and are
  // mirrored alike: keyed by (vertex, other end of the edge, orientation).
  CornerSets sets(m.indices.size());
  std::unordered_map<std::uint64_t, std::uint32_t> first_at_edge[2];  // by orientation
  for (auto& map : first_at_edge) map.reserve(m.indices.size());
  for (std::size_t f = 0; f < tris; ++f)
    for (int c = 0; c < 3; ++c) {
      const auto corner = static_cast<std::uint32_t>(3 * f + static_cast<std::size_t>(c));
      const std::uint32_t v = m.indices[corner];
      for (const int other : {(c + 1) % 3, (c + 2) % 3}) {
        const std::uint32_t w = m.indices[3 * f + static_cast<std::size_t>(other)];
        const std::uint64_t key = static_cast<std::uint64_t>(v) << 32 | w;
        const auto [it, inserted] = first_at_edge[keeps[f]].try_emplace(key, corner);
        if (!inserted) sets.join(it->second, corner);
      }
    }
  // Each group's sum of angle-weighted tangents, kept at its root corner.
  std::vector<Vec3> sum(m.indices.size(), Vec3{0, 0, 0});
  for (std::size_t f = 0; f < tris; ++f) {
    if (degenerate[f]) continue;
    for (int c = 0; c < 3; ++c) {
      const std::size_t corner = 3 * f + static_cast<std::size_t>(c);
      const std::uint32_t v = m.indices[corner];
      const Vec3 n = normalize(m.normals[v]);
      const Vec3 p = m.positions[v];
      const Vec3 e1 = in_plane(m.positions[m.indices[3 * f + static_cast<std::size_t>((c + 1) % 3)]] - p, n);
      const Vec3 e2 = in_plane(m.positions[m.indices[3 * f + static_cast<std::size_t>((c + 2) % 3)]] - p, n);
      const float angle = std::acos(std::clamp(dot(e1, e2), -1.0f, 1.0f));
      sum[sets.find(static_cast<std::uint32_t>(corner))] += in_plane(face_t[f], n) * angle;
    }
  }
  std::vector<CornerTangent> out(m.indices.size());
  for (std::size_t corner = 0; corner < m.indices.size(); ++corner) {
    const Vec3 n = normalize(m.normals[m.indices[corner]]);
    const Vec3 t = in_plane(sum[sets.find(static_cast<std::uint32_t>(corner))], n);
    out[corner] = {length(t) > 0 ? t : perpendicular(n), keeps[corner / 3] ? 1.0f : -1.0f};
  }
  return out;
}

namespace {

// Barycentrics of point q in the 2-D triangle a b c (may be negative outside it); false when the
// triangle is degenerate.
bool barycentrics(Vec2 q, Vec2 a, Vec2 b, Vec2 c, Vec3& w) {
  const double d = (static_cast<double>(b.x) - a.x) * (c.y - a.y) - (static_cast<double>(c.x) - a.x) * (b.y - a.y);
  if (!(std::abs(d) > 0)) return false;
  const double w1 = ((static_cast<double>(q.x) - a.x) * (c.y - a.y) - (static_cast<double>(c.x) - a.x) * (q.y - a.y)) / d;
  const double w2 = ((static_cast<double>(b.x) - a.x) * (q.y - a.y) - (static_cast<double>(q.x) - a.x) * (b.y - a.y)) / d;
  w = {static_cast<float>(1.0 - w1 - w2), static_cast<float>(w1), static_cast<float>(w2)};
  return true;
}

// w clamped into the triangle: negative weights to zero, the rest rescaled to sum to one.
Vec3 clamp_into_triangle(Vec3 w) {
  w = {std::max(w.x, 0.0f), std::max(w.y, 0.0f), std::max(w.z, 0.0f)};
  const float s = w.x + w.y + w.z;
  return s > 0 ? w / s : Vec3{1.0f / 3, 1.0f / 3, 1.0f / 3};
}

// Texel `texel`'s frame from its fragments, into `out`: the fragment whose UV triangle holds the
// texel's centre (the largest, if several), else the one nearest to it, clamped into it.
void texel_frame(const Scene& scene, const TexelCoverage& cov, const std::vector<std::vector<CornerTangent>>& tangents, std::size_t texel,
                 std::span<const TexelPiece> pieces, TexelFrames& out) {
  const Vec2 centre{static_cast<float>(texel % static_cast<std::size_t>(cov.width)) + 0.5f,
                    static_cast<float>(texel / static_cast<std::size_t>(cov.width)) + 0.5f};
  const TexelFragment* pick = nullptr;
  Vec3 w{};
  bool inside = false;
  for (const TexelPiece& piece : pieces) {
    const TexelFragment& f = piece.fragment;
    const Mesh& m = scene.meshes[f.mesh];
    const std::uint32_t* i = &m.indices[3 * static_cast<std::size_t>(f.triangle)];
    Vec3 fw;
    if (!barycentrics(centre, texel_uv(m, i[0], cov.width, cov.height), texel_uv(m, i[1], cov.width, cov.height),
                      texel_uv(m, i[2], cov.width, cov.height), fw))
      continue;
    const bool holds = fw.x >= 0 && fw.y >= 0 && fw.z >= 0;
    if (!pick || (holds && !inside) || (holds == inside && f.uv_area > pick->uv_area)) pick = &f, w = fw, inside = holds;
  }
  if (!pick) return;
  if (!inside) w = clamp_into_triangle(w);
  const Mesh& m = scene.meshes[pick->mesh];
  const std::vector<CornerTangent>& ct = tangents[pick->mesh];
  const std::size_t base = 3 * static_cast<std::size_t>(pick->triangle);
  Vec3 t{0, 0, 0}, n{0, 0, 0};
  for (int c = 0; c < 3; ++c) {
    const float wc = w[c];
    t += ct[base + static_cast<std::size_t>(c)].t * wc;
    n += m.normals[m.indices[base + static_cast<std::size_t>(c)]] * wc;
  }
  out.t[texel] = t, out.n[texel] = n, out.sign[texel] = ct[base].sign;
}

}  // namespace

TexelFrames texel_frames(const Scene& scene, const TexelCoverage& cov, const std::vector<std::vector<CornerTangent>>& tangents) {
  TexelFrames out{Image<Vec3>(cov.width, cov.height, Vec3{0, 0, 0}), Image<Vec3>(cov.width, cov.height, Vec3{0, 0, 0}),
                  Image<float>(cov.width, cov.height, 1.0f)};
  BinFragments bin;
  for_each_covered_texel(scene, cov, 0, 0, cov.width, cov.height, bin, [&](int, int, std::size_t texel, std::span<const TexelPiece> fragments) {
    texel_frame(scene, cov, tangents, texel, fragments, out);
  });
  return out;
}

Vec3 to_tangent_space(Vec3 w, Vec3 t, Vec3 n, float sign) {
  const Vec3 b = cross(n, t) * sign;
  // Solve [t b n] x = w by Cramer's rule: x_i = det(columns with w in place of column i) / det.
  const float det = dot(t, cross(b, n));
  if (!(std::abs(det) > 1e-12f) || !(length(w) > 0)) return {0, 0, 1};
  const Vec3 x{dot(w, cross(b, n)) / det, dot(t, cross(w, n)) / det, dot(t, cross(b, w)) / det};
  return normalize(x);
}

}  // namespace ao
