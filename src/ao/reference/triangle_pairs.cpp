// SPDX-License-Identifier: Apache-2.0
// Greedy pairing of a mesh's triangles into quads across shared edges (triangle_pairs_internal.h).
#include "ao/reference/triangle_pairs_internal.h"

#include <algorithm>
#include <array>
#include <bit>
#include <compare>
#include <cstddef>
#include <numeric>
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

/// A directed edge c -> c + 1 of a triangle, in the list of the edges whose lower position id is
/// the same: `hi` its other end's id, at = 4 tri + c, forward: it runs lo -> hi.
struct Edge {
  std::uint32_t hi;
  std::uint32_t at;
  bool forward;
  std::uint32_t tri() const { return at >> 2; }
  int corner() const { return static_cast<int>(at & 3u); }
};

/// The mesh's directed edges by their ends' position ids (lo, hi), lo < hi, each pair's edges in
/// triangle then corner order: the edges of lo are edges[offsets[lo] .. offsets[lo + 1]). A
/// counting sort by lo (the edges are made in (triangle, corner) order, so each list starts in
/// that order), then each list sorted stably by hi: lists are a vertex's edges, a handful.
struct EdgeLists {
  std::vector<std::uint32_t> offsets;
  std::vector<Edge> edges;
};

EdgeLists edge_lists(const Mesh& m, const std::vector<std::uint32_t>& id) {
  const std::size_t nt = m.triangle_count();
  const auto ends = [&](std::size_t t, int c) {
    return std::make_pair(id[m.indices[3 * t + static_cast<std::size_t>(c)]], id[m.indices[3 * t + static_cast<std::size_t>((c + 1) % 3)]]);
  };
  EdgeLists out;
  out.offsets.assign(id.size() + 1, 0);
  for (std::size_t t = 0; t < nt; ++t)
    for (int c = 0; c < 3; ++c)
      if (const auto [p, q] = ends(t, c); p != q) ++out.offsets[std::min(p, q) + 1];  // a collapsed edge joins nothing
  for (std::size_t v = 0; v < id.size(); ++v) out.offsets[v + 1] += out.offsets[v];
  out.edges.resize(out.offsets.back());
  std::vector<std::uint32_t> cursor(out.offsets.begin(), out.offsets.end() - 1);
  for (std::size_t t = 0; t < nt; ++t)
    for (int c = 0; c < 3; ++c)
      if (const auto [p, q] = ends(t, c); p != q)
        out.edges[cursor[std::min(p, q)]++] = {std::max(p, q), static_cast<std::uint32_t>(4 * t + static_cast<std::size_t>(c)), p < q};
  const auto by_hi = [](const Edge& x, const Edge& y) { return x.hi < y.hi; };
  for (std::size_t v = 0; v < id.size(); ++v) {
    const auto first = out.edges.begin() + out.offsets[v], last = out.edges.begin() + out.offsets[v + 1];
    if (last - first > 32) {
      std::stable_sort(first, last, by_hi);  // a fan's hub, a pole
      continue;
    }
    for (auto i = first + 1; i < last; ++i)  // insertion sort: stable, no buffer
      for (auto j = i; j > first && by_hi(*j, *(j - 1)); --j) std::iter_swap(j, j - 1);
  }
  return out;
}

/// A candidate pair as two integers, ordered as the greedy pass takes them: its quad's cost (a
/// non-negative float, whose bits order as it does; a NaN, from boxes of infinite area, after
/// every number), then its triangles a < b, then the corners where the shared edge starts in each.
struct CandidateKey {
  std::uint64_t cost_a;                 // cost's bits, a
  std::uint64_t b_corners;              // b, corner_a, corner_b
  auto operator<=>(const CandidateKey&) const = default;
  std::uint32_t a() const { return static_cast<std::uint32_t>(cost_a); }
  std::uint32_t b() const { return static_cast<std::uint32_t>(b_corners >> 32); }
  std::uint8_t corner_a() const { return static_cast<std::uint8_t>(b_corners >> 8); }
  std::uint8_t corner_b() const { return static_cast<std::uint8_t>(b_corners); }
};
CandidateKey candidate_key(float cost, std::uint32_t a, std::uint32_t b, std::uint8_t corner_a, std::uint8_t corner_b) {
  return {std::uint64_t{std::bit_cast<std::uint32_t>(cost)} << 32 | a, std::uint64_t{b} << 32 | std::uint64_t{corner_a} << 8 | corner_b};
}

}  // namespace

TrianglePairs pair_triangles(const Mesh& m) {
  const std::size_t nt = m.triangle_count();
  const EdgeLists lists = edge_lists(m, position_ids(m));
  const auto vertex = [&](std::size_t t, int c) { return m.indices[3 * t + static_cast<std::size_t>(c % 3)]; };

  // Candidates: two different triangles on one edge, running it in opposite directions. An edge
  // of more than kMaxFan triangles (non-manifold fans, stacked copies) offers none: its candidates
  // grow with the square of its triangles, and they still pair across their other edges.
  constexpr std::size_t kMaxFan = 8;
  std::vector<CandidateKey> candidates;
  candidates.reserve(lists.edges.size() / 2);
  const std::vector<Edge>& edges = lists.edges;
  for (std::size_t v = 0; v + 1 < lists.offsets.size(); ++v)
    for (std::size_t first = lists.offsets[v], end = lists.offsets[v + 1]; first < end;) {
      std::size_t last = first + 1;
      while (last < end && edges[last].hi == edges[first].hi) ++last;
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
            candidates.push_back(x.tri() < y.tri() ? candidate_key(cost, x.tri(), y.tri(), cx, cy) : candidate_key(cost, y.tri(), x.tri(), cy, cx));
          }
      first = last;
    }
  std::sort(candidates.begin(), candidates.end());

  constexpr std::uint32_t kNone = 0xffffffffu;
  std::vector<std::uint32_t> partner(nt, kNone);
  std::vector<std::uint8_t> corner(nt, 0);  // where the shared edge starts in each paired triangle
  for (const CandidateKey& k : candidates) {
    const std::uint32_t a = k.a(), b = k.b();
    if (partner[a] != kNone || partner[b] != kNone) continue;
    partner[a] = b, partner[b] = a;
    corner[a] = k.corner_a(), corner[b] = k.corner_b();
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
