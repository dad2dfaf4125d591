// SPDX-License-Identifier: Apache-2.0
// Greedy pairing of a mesh's triangles into quads across shared edges (triangle_pairs_internal.h).
#include "ao/reference/triangle_pairs_internal.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <numeric>
#include <tuple>
#include <utility>

#include <tbb/parallel_sort.h>

namespace ao::detail {

namespace {

/// Per vertex, the lowest index of a vertex at bitwise the same position: the ids edges are
/// compared by, so that split vertices (UV seams, hard edges) join.
std::vector<std::uint32_t> position_ids(const Mesh& m) {
  const auto bits = [&](std::uint32_t v) {
    const Vec3& p = m.positions[v];
    return std::array<std::uint32_t, 3>{std::bit_cast<std::uint32_t>(p.x), std::bit_cast<std::uint32_t>(p.y), std::bit_cast<std::uint32_t>(p.z)};
  };
  const auto key = [&](std::uint32_t v) { return std::make_pair(bits(v), v); };
  std::vector<std::uint32_t> order(m.positions.size());
  std::iota(order.begin(), order.end(), 0u);
  tbb::parallel_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
  std::vector<std::uint32_t> id(m.positions.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    const bool same = i > 0 && bits(order[i]) == bits(order[i - 1]);
    id[order[i]] = same ? id[order[i - 1]] : order[i];
  }
  return id;
}

/// Half the surface area of the box around `n` points (the SAH's measure of a leaf).
float box_area(std::initializer_list<Vec3> pts) {
  Vec3 lo = *pts.begin(), hi = lo;
  for (const Vec3& p : pts) lo = min(lo, p), hi = max(hi, p);
  const Vec3 e = hi - lo;
  return e.x * e.y + e.y * e.z + e.z * e.x;
}

/// Directed edge c -> c + 1 of triangle tri (corner c): key = its ends' position ids lo < hi
/// (lo in the high half), at = 4 tri + c, forward: it runs lo -> hi. Sorted by (key, at), all distinct.
struct Edge {
  std::uint64_t key;
  std::uint32_t at;
  bool forward;
  std::uint32_t tri() const { return at >> 2; }
  int corner() const { return static_cast<int>(at & 3u); }
};

struct Candidate {
  float cost;
  std::uint32_t a, b;            // triangles, a < b
  std::uint8_t corner_a, corner_b;  // where the shared edge starts in each
};

}  // namespace

TrianglePairs pair_triangles(const Mesh& m) {
  const std::size_t nt = m.triangle_count();
  const std::vector<std::uint32_t> id = position_ids(m);
  const auto vertex = [&](std::size_t t, int c) { return m.indices[3 * t + static_cast<std::size_t>(c % 3)]; };

  std::vector<Edge> edges;
  edges.reserve(3 * nt);
  for (std::size_t t = 0; t < nt; ++t)
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t p = id[vertex(t, c)], q = id[vertex(t, c + 1)];
      if (p == q) continue;  // a collapsed edge joins nothing
      const std::uint64_t key = (static_cast<std::uint64_t>(std::min(p, q)) << 32) | std::max(p, q);
      edges.push_back({key, static_cast<std::uint32_t>(4 * t + static_cast<std::size_t>(c)), p < q});
    }
  tbb::parallel_sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) { return x.key != y.key ? x.key < y.key : x.at < y.at; });

  // Candidates: two different triangles on one edge, running it in opposite directions. An edge
  // of more than kMaxFan triangles (non-manifold fans, stacked copies) offers none: its candidates
  // grow with the square of its triangles, and they still pair across their other edges.
  constexpr std::size_t kMaxFan = 8;
  std::vector<Candidate> candidates;
  for (std::size_t first = 0; first < edges.size();) {
    std::size_t last = first + 1;
    while (last < edges.size() && edges[last].key == edges[first].key) ++last;
    if (last - first <= kMaxFan)
      for (std::size_t i = first; i < last; ++i)
        for (std::size_t j = i + 1; j < last; ++j) {
          const Edge& x = edges[i];
          const Edge& y = edges[j];
          if (x.tri() == y.tri() || x.forward == y.forward) continue;
          const Vec3 pa = m.positions[vertex(x.tri(), x.corner())], pb = m.positions[vertex(x.tri(), x.corner() + 1)];
          const Vec3 pc = m.positions[vertex(x.tri(), x.corner() + 2)], pd = m.positions[vertex(y.tri(), y.corner() + 2)];
          const float separate = box_area({pa, pb, pc}) + box_area({pa, pb, pd});
          const float cost = separate > 0 ? box_area({pa, pb, pc, pd}) / separate : 0.0f;
          const auto cx = static_cast<std::uint8_t>(x.corner()), cy = static_cast<std::uint8_t>(y.corner());
          if (x.tri() < y.tri()) candidates.push_back({cost, x.tri(), y.tri(), cx, cy});
          else candidates.push_back({cost, y.tri(), x.tri(), cy, cx});
        }
    first = last;
  }
  tbb::parallel_sort(candidates.begin(), candidates.end(),
            [](const Candidate& x, const Candidate& y) { return std::tie(x.cost, x.a, x.b, x.corner_a, x.corner_b) < std::tie(y.cost, y.a, y.b, y.corner_a, y.corner_b); });

  constexpr std::uint32_t kNone = 0xffffffffu;
  std::vector<std::uint32_t> partner(nt, kNone);
  std::vector<std::uint8_t> corner(nt, 0);  // where the shared edge starts in each paired triangle
  for (const Candidate& c : candidates) {
    if (partner[c.a] != kNone || partner[c.b] != kNone) continue;
    partner[c.a] = c.b, partner[c.b] = c.a;
    corner[c.a] = c.corner_a, corner[c.b] = c.corner_b;
  }

  TrianglePairs out;
  out.quads.reserve(4 * nt);
  out.triangles.reserve(2 * nt);
  for (std::size_t t = 0; t < nt; ++t) {
    const std::uint32_t u = partner[t];
    if (u == kNone) {
      // A lone triangle: (v0, v1, v2, v2), which Embree takes as the triangle (v0, v1, v2).
      out.quads.insert(out.quads.end(), {vertex(t, 0), vertex(t, 1), vertex(t, 2), vertex(t, 2)});
      out.triangles.insert(out.triangles.end(), {static_cast<std::uint32_t>(t), static_cast<std::uint32_t>(t)});
      continue;
    }
    if (u < t) continue;  // emitted with its partner
    // Triangle t is (a, b, c) from its shared edge a -> b; its partner runs b -> a and has d
    // opposite. The quad (c, a, d, b) has halves (v0, v1, v3) = (c, a, b), t rotated, and
    // (v2, v3, v1) = (d, b, a), the partner rotated (with t's indices for the shared edge's ends,
    // which are at the same positions as the partner's).
    const std::uint32_t a = vertex(t, corner[t]), b = vertex(t, corner[t] + 1), c = vertex(t, corner[t] + 2);
    const std::uint32_t d = vertex(u, corner[u] + 2);
    out.quads.insert(out.quads.end(), {c, a, d, b});
    out.triangles.insert(out.triangles.end(), {static_cast<std::uint32_t>(t), u});
    out.paired_triangles += 2;
  }
  return out;
}

}  // namespace ao::detail
