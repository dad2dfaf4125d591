// Solid parity voxelization (Eisemann & Decoret 2008; Dalla Favera & Celes 2012, sec. III-B).
// See voxelize.h for the grid layout. The CPU pipeline:
//  1. every triangle is mapped to the
//     grid: column coordinates (x, y) and a depth attribute that is affine in (x, y) (voxel units
//     for the orthographic world grid, 1/depth for the perspective eye grid);
//  2. the rows of columns are split into bands; triangles are bucketed by band (counting sort per
//     chunk); each band rasterises the triangles that overlap it at the column centres and toggles
//     one bit per fragment (no atomics: bands are disjoint);
//  3. one prefix-XOR scan per column turns toggles into "XOR from the fragment to the far end";
//  4. coarse occupancy (blocks and windowed cell masks, voxelize.h) for empty-space skipping.
#include "ao/methods/cone/voxelize.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <mutex>
#include <tuple>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "ao/core/error.h"
#include "ao/methods/cone/voxel_raster_internal.h"
#include "ao/simd/bits_internal.h"
#include "ao/methods/cone/raster_kernel_internal.h"

namespace ao {

using voxel_internal::ColumnHit;
using voxel_internal::GridTri;
using voxel_internal::PrismCounts;

namespace {

constexpr std::size_t kChunk = 4096;  // triangles per projection task
constexpr int kBands = 48;            // row bands of the raster stage: enough to balance 2-16 threads

struct Tri3 {
  Vec3 v[3];
  int kind;      // 0: parity; 1: open-mesh face, filled behind `normal`; 2: side of an open face's prism
  Vec3 normal;   // kind 1: the side the slab is away from (the front's normal, or its opposite for
                 // a grid traced from the back side, voxelize.h)
  int fan = -1;  // kind 0: slot of the solid with holes whose non-flat hole this fan triangle closes,
                 // or near which this triangle of it lies (Holes::near)
};

// The centroid of each hole's boundary vertices (each boundary edge contributes its two ends), and
// whether the hole is flat to the grid: its boundary within `flat` (world units: two voxels) of the
// plane through the centroid normal to the fan's vector area. Off a flat fan |w_fan| < 1/2
// (voxelize_world), so the parity of the mesh with its fans is its winding-number solid there;
// within two voxels of a plane, the pocket between the fan and the surface w = 1/2 that spans the
// hole lies in a sliver of that thickness along the plane (a scan's base cut through its
// triangles zigzags by a triangle's height), which is left to parity.
// `near` marks the mesh's triangles near the rim of a hole that is not flat: where the pocket
// between that hole's fan and its spanning surface can meet the mesh.
struct Holes {
  std::vector<Vec3> centre;
  std::vector<std::uint8_t> flat;
  std::vector<std::uint8_t> near;  // per triangle
};
Holes hole_centroids(const Mesh& m, const MeshClosure& c, float flat) {
  Holes h{std::vector<Vec3>(c.holes, Vec3{0, 0, 0}), std::vector<std::uint8_t>(c.holes, 1), std::vector<std::uint8_t>(m.triangle_count(), 0)};
  std::vector<float> n(c.holes, 0.0f);
  for (std::size_t e = 0; e < c.boundary.size(); ++e) {
    h.centre[c.hole[e]] += m.positions[c.boundary[e][0]] + m.positions[c.boundary[e][1]];
    n[c.hole[e]] += 2.0f;
  }
  for (std::uint32_t k = 0; k < c.holes; ++k) h.centre[k] = h.centre[k] * (1.0f / n[k]);
  std::vector<Vec3> area(c.holes, Vec3{0, 0, 0});
  std::vector<Bounds3> box(c.holes);
  for (std::size_t e = 0; e < c.boundary.size(); ++e) {
    const Vec3 o = h.centre[c.hole[e]];
    area[c.hole[e]] += cross(m.positions[c.boundary[e][1]] - o, m.positions[c.boundary[e][0]] - o);
    box[c.hole[e]].extend(m.positions[c.boundary[e][0]]);
  }
  const float extent = m.bounds().diagonal(), tol = flat, pad = 0.01f * extent;
  for (std::size_t e = 0; e < c.boundary.size(); ++e) {
    const std::uint32_t k = c.hole[e];
    const Vec3 nk = normalize(area[k]);
    for (int end = 0; end < 2; ++end)
      if (!(std::abs(dot(nk, m.positions[c.boundary[e][end]] - h.centre[k])) <= tol)) h.flat[k] = 0;
  }
  // Near a hole: within its rim's deviation from its plane (how far the pocket reaches from the
  // rim) plus 1% of the mesh's extent of one of its rim vertices.
  std::vector<float> deviation(c.holes, 0.0f);
  for (std::size_t e = 0; e < c.boundary.size(); ++e) {
    const std::uint32_t k = c.hole[e];
    deviation[k] = std::max(deviation[k], std::abs(dot(normalize(area[k]), m.positions[c.boundary[e][0]] - h.centre[k])));
  }
  for (std::uint32_t k = 0; k < c.holes; ++k) {
    if (h.flat[k]) continue;
    const float reach = deviation[k] + pad;
    const Vec3 lo = box[k].lo - Vec3{reach, reach, reach}, hi = box[k].hi + Vec3{reach, reach, reach};
    for (std::size_t t = 0; t < m.triangle_count(); ++t)
      for (int v = 0; v < 3 && !h.near[t]; ++v) {
        const Vec3 p = m.positions[m.indices[3 * t + v]];
        if (p.x < lo.x || p.y < lo.y || p.z < lo.z || p.x > hi.x || p.y > hi.y || p.z > hi.z) continue;
        for (std::size_t e = 0; e < c.boundary.size() && !h.near[t]; ++e)
          if (c.hole[e] == k && length(p - m.positions[c.boundary[e][0]]) <= reach) h.near[t] = 1;
      }
  }
  return h;
}

// The winding number w_C of one mesh's fans (the triangles (b, a, centroid) over its boundary
// edges a -> b), summed exactly with Van Oosterom and Strackee's formula (winding_number.h): fan
// triangles are slivers from the rim to the centroid, which a hierarchy cannot group. The rim's
// vertices are shared by two edges each, so their offsets and lengths are computed once per point.
struct FanWinding {
  std::vector<Vec3> vertex;                      // rim vertices, then the holes' centroids
  std::vector<std::array<std::uint32_t, 3>> tri;  // (b, a, centroid) into `vertex`
  double operator()(Vec3 q, std::vector<Vec3>& r, std::vector<float>& len) const {
    r.resize(vertex.size());
    len.resize(vertex.size());
    for (std::size_t v = 0; v < vertex.size(); ++v) r[v] = vertex[v] - q, len[v] = length(r[v]);
    double sum = 0;
    for (const auto& [b, a, c] : tri) {
      const float det = dot(r[b], cross(r[a], r[c]));
      if (det == 0.0f) continue;  // q in the triangle's plane: 0 (winding_number.cpp)
      const float den = len[b] * len[a] * len[c] + dot(r[b], r[a]) * len[c] + dot(r[b], r[c]) * len[a] + dot(r[a], r[c]) * len[b];
      sum += std::atan2(det, den);
    }
    return sum * (2.0 / (4.0 * 3.14159265358979323846));
  }
};
FanWinding fan_winding(const Mesh& m, const MeshClosure& c, const Holes& h) {
  FanWinding f;
  std::vector<std::uint32_t> slot(m.positions.size(), ~0u);
  const auto at = [&](std::uint32_t v) {
    if (slot[v] == ~0u) slot[v] = static_cast<std::uint32_t>(f.vertex.size()), f.vertex.push_back(m.positions[v]);
    return slot[v];
  };
  for (std::size_t e = 0; e < c.boundary.size(); ++e) f.tri.push_back({at(c.boundary[e][1]), at(c.boundary[e][0]), 0});
  const std::uint32_t first_centre = static_cast<std::uint32_t>(f.vertex.size());
  f.vertex.insert(f.vertex.end(), h.centre.begin(), h.centre.end());
  for (std::size_t e = 0; e < c.boundary.size(); ++e) f.tri[e][2] = first_centre + c.hole[e];
  return f;
}

Tri3 source_triangle(const Mesh& m, std::size_t t, bool open) {
  const Vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]], c = m.positions[m.indices[3 * t + 2]];
  return {{a, b, c}, open ? 1 : 0, open ? normalize(cross(b - a, c - a)) : Vec3{}};
}

// An open face steep to the columns (a wall, for the world grid) has few or no fragments: a span
// along the column cannot stand for it. It becomes the closed prism between it and its copy
// moved `thickness` behind `normal` (kind 2), whose triangles face out of it; their union is
// ORed into the grid (voxelize_into, step 4). Calls emit for the prism's 8 triangles.
template <class Emit>
void emit_prism(const Tri3& t, float thickness, Emit&& emit) {
  const Vec3 o = t.normal * -thickness;
  // The top (the face itself) faces out when its counter-clockwise normal is `normal`; otherwise
  // (a slab in front of a face) its vertices are taken in the other order.
  const bool out = dot(cross(t.v[1] - t.v[0], t.v[2] - t.v[0]), t.normal) >= 0;
  const Vec3 a = t.v[0], b = out ? t.v[1] : t.v[2], c = out ? t.v[2] : t.v[1];
  const Vec3 top[3] = {a, b, c}, bottom[3] = {a + o, b + o, c + o};
  emit(Tri3{{top[0], top[1], top[2]}, 2, {}});
  emit(Tri3{{bottom[0], bottom[2], bottom[1]}, 2, {}});
  for (int e = 0; e < 3; ++e) {
    const int f = (e + 1) % 3;
    emit(Tri3{{top[e], bottom[e], bottom[f]}, 2, {}});
    emit(Tri3{{top[e], bottom[f], top[f]}, 2, {}});
  }
}

// |cos| of the angle between an open face and the column direction below which it is a wall.
constexpr float kSteep = 0.5f;

// Grid-space mapping of the two grids. map() returns false for a vertex that needs clipping.
struct WorldMap {
  Vec3 origin, inv_size;
  float slab;
  void operator()(Vec3 p, float& x, float& y, float& a) const {
    x = (p.x - origin.x) * inv_size.x;
    y = (p.z - origin.z) * inv_size.y;
    a = (p.y - origin.y) * inv_size.z;
  }
};

struct EyeMap {
  Frame basis;
  Vec3 eye;
  float sx, sy, ox, oy;  // column = (x / depth) * sx + ox, (y / depth) * sy + oy
  float z_clip;
  float slab;
};

// Sets the rows of a mapped triangle; false when no column centre of the grid can be inside.
bool finish_visible(GridTri& t, int nx, int ny) {
  const float xmin = std::min({t.x[0], t.x[1], t.x[2]}), xmax = std::max({t.x[0], t.x[1], t.x[2]});
  const float ymin = std::min({t.y[0], t.y[1], t.y[2]}), ymax = std::max({t.y[0], t.y[1], t.y[2]});
  // Column i's centre is i + 0.5: the box covers i in [ceil(min - 0.5), floor(max - 0.5)].
  if (!(xmax >= 0.5f && xmin <= static_cast<float>(nx) - 0.5f)) return false;  // also rejects NaN
  if (!(ymax >= ymin)) return false;                                           // NaN
  // Rows: the rounding of the ends clamped to [-2, ny + 1] first, where truncation does it (a
  // baseline x86-64 build has no rounding instruction, and this runs once per triangle); ends
  // beyond that range are rejected or clamped to the grid alike.
  const float lo = std::clamp(ymin - 0.5f, -2.0f, static_cast<float>(ny + 1)), hi = std::clamp(ymax - 0.5f, -2.0f, static_cast<float>(ny + 1));
  const int tl = static_cast<int>(lo), th = static_cast<int>(hi);
  const int j0 = tl + (static_cast<float>(tl) < lo ? 1 : 0), j1 = th - (static_cast<float>(th) > hi ? 1 : 0);  // ceil, floor
  if (j1 < 0 || j0 > ny - 1 || j0 > j1) return false;
  t.j0 = std::max(j0, 0);
  t.j1 = std::min(j1, ny - 1);
  return true;
}

void push_if_visible(std::vector<GridTri>& out, const GridTri& g, int nx, int ny) {
  GridTri t = g;
  if (finish_visible(t, nx, ny)) out.push_back(t);
}

void emit_world(std::vector<GridTri>& out, const Tri3& t, const WorldMap& m, int nx, int ny) {
  if (t.kind == 1 && std::abs(t.normal.y) < kSteep)
    return emit_prism(t, m.slab, [&](const Tri3& side) { emit_world(out, side, m, nx, ny); });
  // Built in place: a copy of a struct just written field by field stalls on store forwarding.
  GridTri& g = out.emplace_back();
  for (int k = 0; k < 3; ++k) m(t.v[k], g.x[k], g.y[k], g.a[k]);
  // Behind the front face: below a face looking up (+y is +k), above a face looking down.
  g.fill = t.kind == 1 ? (t.normal.y > 0 ? -1 : 1) : t.kind == 2 ? 2 : t.fan >= 0 ? 3 + t.fan : 0;
  if (!finish_visible(g, nx, ny)) out.pop_back();
}

// Perspective: clip against depth >= z_clip (Sutherland-Hodgman on one plane), project, and
// keep 1/depth as the attribute, which is affine in screen space.
void emit_eye(std::vector<GridTri>& out, const Tri3& t, const EyeMap& m, int nx, int ny) {
  std::array<Vec3, 4> poly;
  int n = 0;
  Vec3 c[3];
  for (int k = 0; k < 3; ++k) c[k] = m.basis.to_local(t.v[k] - m.eye);
  const float facing = t.kind == 1 ? dot(m.basis.to_local(t.normal), normalize(c[0] + c[1] + c[2])) : 0.0f;
  if (t.kind == 1 && std::abs(facing) < kSteep)
    return emit_prism(t, m.slab, [&](const Tri3& side) { emit_eye(out, side, m, nx, ny); });
  for (int k = 0; k < 3; ++k) {
    const Vec3 p = c[k], q = c[(k + 1) % 3];
    const float dp = -p.z - m.z_clip, dq = -q.z - m.z_clip;
    if (dp >= 0) poly[n++] = p;
    if ((dp >= 0) != (dq >= 0)) poly[n++] = p + (q - p) * (dp / (dp - dq));
  }
  if (n < 3) return;
  // Behind the front face: deeper for a face turned to the eye, nearer for one turned away.
  const int fill = t.kind == 1 ? (facing < 0 ? 1 : -1) : t.kind == 2 ? 2 : t.fan >= 0 ? 3 + t.fan : 0;
  float x[4], y[4], a[4];
  for (int k = 0; k < n; ++k) {
    const float inv = 1.0f / -poly[k].z;
    x[k] = poly[k].x * inv * m.sx + m.ox;
    y[k] = poly[k].y * inv * m.sy + m.oy;
    a[k] = inv;
  }
  for (int k = 1; k + 1 < n; ++k) {
    GridTri g{{x[0], x[k], x[k + 1]}, {y[0], y[k], y[k + 1]}, {a[0], a[k], a[k + 1]}, 0, 0, fill};
    push_if_visible(out, g, nx, ny);
  }
}

// Prefix XOR along every column: bit k becomes the XOR of toggles 0..k. Returns odd columns.
// Two passes per row of columns (the row stays in L1): the prefix XOR inside every word, a flat
// pass over the row's words in a SIMD kernel (simd::prefix_xor_in_words, simd/bits_kernel.cpp), then the carry between
// the words of each column (the top bit of a word is the parity of the column so far).
std::size_t scan_columns(VoxelGrid& g) {
  const int words = g.words, nbits = g.depth_bits;
  const int last_bits = nbits - 64 * (words - 1);
  const std::uint64_t last_mask = last_bits == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << last_bits) - 1;
  std::vector<std::size_t> odd_per_row(g.ny, 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, g.ny, 8), [&](const tbb::blocked_range<int>& r) {
    const std::size_t row_words = static_cast<std::size_t>(g.nx) * words;
    for (int j = r.begin(); j < r.end(); ++j) {
      std::uint64_t* row = g.bits.data() + static_cast<std::size_t>(j) * row_words;
      simd::prefix_xor_in_words(row, row_words);
      std::size_t odd = 0;
      for (int i = 0; i < g.nx; ++i) {
        std::uint64_t* col = row + static_cast<std::size_t>(i) * words;
        std::uint64_t carry = 0;  // all ones when the previous words left the column inside
        for (int w = 0; w < words; ++w) {
          const std::uint64_t x = col[w] ^ carry;
          carry = static_cast<std::uint64_t>(static_cast<std::int64_t>(x) >> 63);
          col[w] = x;
        }
        std::uint64_t& last = col[words - 1];
        odd += (last >> (last_bits - 1)) & 1u;
        last &= last_mask;  // keep the unused high bits of the last word zero for popcount
      }
      odd_per_row[j] = odd;
    }
  });
  std::size_t odd = 0;
  for (std::size_t o : odd_per_row) odd += o;
  return odd;
}

// Coarse occupancy for empty-space skipping, in one pass over the grid: the OR of each cell of
// kCellXY x kCellXY columns (all words), from which the blocks (2 x 2 cells, all words) and the
// cells' 64-bit masks along the column (one bit per cell_bits voxels), ORed over the square
// windows of 1..kWindowCap + 1 cells anchored at each cell. Returns the number of solid voxels.
std::size_t build_coarse(VoxelGrid& g) {
  constexpr int C = VoxelGrid::kCellXY, B = VoxelGrid::kBlock;
  static_assert(B == 2 * C);
  const int words = g.words;
  int cb = 1;
  while (cb * 64 < g.depth_bits) cb *= 2;
  g.cell_bits = cb;
  g.cell_shift = std::countr_zero(static_cast<unsigned>(cb));
  g.dnx = (g.nx + C - 1) / C;
  g.dny = (g.ny + C - 1) / C;
  g.bnx = (g.nx + B - 1) / B;
  g.bny = (g.ny + B - 1) / B;
  const int dnx = g.dnx, dny = g.dny;
  const std::size_t cells = static_cast<std::size_t>(dnx) * dny;
  std::vector<std::uint64_t> cell_words(cells * words, 0);
  constexpr int L = VoxelGrid::kWindowCap + 1;
  std::vector<std::uint64_t> level(cells * L);  // window w at [w * cells, (w + 1) * cells), then interleaved
  std::uint64_t* m0 = level.data();
  std::vector<std::size_t> set_per_row(dny, 0);
  tbb::parallel_for(0, dny, [&](int cj) {
    const std::size_t row_words = static_cast<std::size_t>(g.nx) * words;
    std::vector<std::uint64_t> acc(row_words, 0);
    std::size_t set = 0;
    for (int j = cj * C; j < std::min(g.ny, (cj + 1) * C); ++j) {
      set += simd::or_into_and_count(acc.data(), g.column(0, j), row_words);
    }
    set_per_row[cj] = set;
    for (int ci = 0; ci < dnx; ++ci) {
      std::uint64_t* out = cell_words.data() + (static_cast<std::size_t>(cj) * dnx + ci) * words;
      for (int i = ci * C; i < std::min(g.nx, (ci + 1) * C); ++i)
        for (int w = 0; w < words; ++w) out[w] |= acc[static_cast<std::size_t>(i) * words + w];
      std::uint64_t m = 0;
      if (cb == 1) {
        m = out[0];
      } else {
        const int per_word = 64 / cb;
        for (int w = 0; w < words; ++w) {
          std::uint64_t x = out[w];
          for (int f = 1; f < cb; f <<= 1) x |= x >> f;  // bit q * cb: OR of its cell's voxels
          for (int q = 0; q < per_word; ++q) m |= ((x >> (q * cb)) & 1u) << (w * per_word + q);
        }
      }
      m0[static_cast<std::size_t>(cj) * dnx + ci] = m;
    }
  });
  g.block_bits.assign(static_cast<std::size_t>(g.bnx) * g.bny * words, 0);
  for (int cj = 0; cj < dny; ++cj)
    for (int ci = 0; ci < dnx; ++ci) {
      std::uint64_t* blk = g.block_bits.data() + (static_cast<std::size_t>(cj / 2) * g.bnx + ci / 2) * words;
      const std::uint64_t* cw = cell_words.data() + (static_cast<std::size_t>(cj) * dnx + ci) * words;
      for (int w = 0; w < words; ++w) blk[w] |= cw[w];
    }
  // Windows of w + 1 cells: the OR along i of cells ci..ci + w (row w = row w - 1 | cell ci + w),
  // then the OR of those over the rows cj..cj + w.
  std::vector<std::uint64_t> rows(cells * L);
  for (std::size_t c = 0; c < cells; ++c) rows[c] = m0[c];
  for (int w = 1; w < L; ++w)
    for (int cj = 0; cj < dny; ++cj)
      for (int ci = 0; ci < dnx; ++ci) {
        const std::size_t c = static_cast<std::size_t>(cj) * dnx + ci;
        rows[w * cells + c] = rows[(w - 1) * cells + c] | (ci + w < dnx ? m0[c + w] : 0);
      }
  for (int w = 1; w < L; ++w)
    for (int cj = 0; cj < dny; ++cj)
      for (int ci = 0; ci < dnx; ++ci) {
        std::uint64_t m = 0;
        for (int j = cj; j <= std::min(cj + w, dny - 1); ++j) m |= rows[w * cells + static_cast<std::size_t>(j) * dnx + ci];
        level[w * cells + static_cast<std::size_t>(cj) * dnx + ci] = m;
      }
  g.window.resize(cells * L);
  for (std::size_t c = 0; c < cells; ++c)
    for (int w = 0; w < L; ++w) g.window[c * L + w] = level[w * cells + c];
  std::size_t set = 0;
  for (std::size_t n : set_per_row) set += n;
  return set;
}

// How one object is voxelized (voxelize.h: OpenMeshes, and the `back` side of a grid).
enum class Treat : std::uint8_t {
  Parity,       // as it is
  Fans,         // a solid with holes: parity with its holes closed by fans, w evaluated near non-flat ones
  Slab,         // a slab behind its fronts
  SlabFlipped,  // a slab in front of its fronts
};

// Per object, and the number of open objects voxelized for their back side.
struct Treatments {
  std::vector<Treat> of;
  std::size_t back = 0;
};
Treatments treatments(const Scene& scene, std::span<const MeshClosure> closure, OpenMeshes mode, std::span<const std::uint8_t> back) {
  if (closure.size() != scene.meshes.size()) throw InputError("voxelize: closure has " + std::to_string(closure.size()) +
                                                              " meshes, the scene " + std::to_string(scene.meshes.size()));
  const std::vector<SceneObject> objects = scene.objects();
  if (!back.empty() && back.size() != objects.size())
    throw InputError("voxelize: " + std::to_string(back.size()) + " back-side flags for " + std::to_string(objects.size()) + " objects");
  Treatments r{std::vector<Treat>(objects.size(), Treat::Parity), 0};
  std::vector<Treat>& t = r.of;
  for (std::size_t o = 0; o < objects.size(); ++o) {
    const MeshClosure& c = closure[objects[o].mesh];
    const bool from_back = mode == OpenMeshes::Winding && !c.closed() && !back.empty() && back[o];
    r.back += from_back ? 1 : 0;
    if (mode == OpenMeshes::Slab && c.open_surface()) {
      t[o] = Treat::Slab;
    } else if (mode == OpenMeshes::Winding && c.open_surface()) {
      t[o] = from_back ? Treat::SlabFlipped : Treat::Slab;
    } else if (mode == OpenMeshes::Winding && c.holed()) {
      // Seen from inside (through a hole), the shell's outside is what occludes: a slab on the
      // side its fronts face when they face out.
      const Affine3* tf = objects[o].instance == SceneObject::kNoInstance ? nullptr : &scene.instances[objects[o].instance].object_to_world;
      const int out = c.orientation * (tf && tf->determinant() < 0 ? -1 : 1);
      t[o] = !from_back ? Treat::Fans : out > 0 ? Treat::SlabFlipped : Treat::Slab;
    }
  }
  return r;
}

bool any_slab(std::span<const Treat> t) {
  return std::any_of(t.begin(), t.end(), [](Treat x) { return x == Treat::Slab || x == Treat::SlabFlipped; });
}

// Whether a slab rises above any face (world +y): a face turned down with a slab behind it, or
// turned up with one in front.
bool slab_rises(const Scene& scene, std::span<const Treat> t) {
  const std::vector<SceneObject> objects = scene.objects();
  for (std::size_t o = 0; o < objects.size(); ++o) {
    if (t[o] != Treat::Slab && t[o] != Treat::SlabFlipped) continue;
    const Mesh& m = scene.meshes[objects[o].mesh];
    const Affine3* tf = objects[o].instance == SceneObject::kNoInstance ? nullptr : &scene.instances[objects[o].instance].object_to_world;
    const float side = t[o] == Treat::Slab ? 1.0f : -1.0f;
    for (std::size_t k = 0; k < m.triangle_count(); ++k) {
      Vec3 v[3] = {m.positions[m.indices[3 * k]], m.positions[m.indices[3 * k + 1]], m.positions[m.indices[3 * k + 2]]};
      if (tf)
        for (Vec3& p : v) p = tf->point(p);
      if (side * cross(v[1] - v[0], v[2] - v[0]).y < 0) return true;
    }
  }
  return false;
}

// Object space of an object: the inverse of its instance's map (identity for a world-space mesh),
// and the sign of its determinant (a mirror turns fronts into backs: w changes sign).
struct ObjectSpace {
  bool instanced = false;
  Affine3 to_object;
  int sign = 1;
  Vec3 operator()(Vec3 p) const { return instanced ? to_object.point(p) : p; }
};
ObjectSpace object_space(const Scene& scene, const SceneObject& ob) {
  if (ob.instance == SceneObject::kNoInstance) return {};
  const Affine3& m = scene.instances[ob.instance].object_to_world;
  return {true, inverse(m), m.determinant() < 0 ? -1 : 1};
}

// Row bands of the raster stage (kBands, fewer for a short grid) and the band of each row.
struct Bands {
  int ny = 0, count = 0;
  std::vector<int> of;  // per row
  int first_row(int b) const { return static_cast<int>(static_cast<long long>(ny) * b / count); }
};
Bands make_bands(int ny) {
  Bands b{ny, std::min(ny, kBands), std::vector<int>(ny)};
  for (int k = 0; k < b.count; ++k)
    for (int j = b.first_row(k); j < b.first_row(k + 1); ++j) b.of[j] = k;
  return b;
}

// A chunk's triangles bucketed by (fill kind, row band), a counting sort: bucket
// kind * bands + band is index[start[k], start[k + 1]); a triangle spanning bands is in each.
struct Buckets {
  std::vector<std::uint32_t> start, index;
};
// Fill kinds: 0 parity (fans included), 1 slab spans, 2 prisms (GridTri::fill).
int kind_of(const GridTri& t) { return t.fill == 0 || t.fill >= 3 ? 0 : t.fill == 2 ? 2 : 1; }
Buckets bucket(const std::vector<GridTri>& tris, const Bands& bands) {
  Buckets bk;
  bk.start.assign(3 * static_cast<std::size_t>(bands.count) + 1, 0);
  for (const GridTri& t : tris)
    for (int b = bands.of[t.j0]; b <= bands.of[t.j1]; ++b) ++bk.start[kind_of(t) * bands.count + b + 1];
  for (std::size_t k = 1; k < bk.start.size(); ++k) bk.start[k] += bk.start[k - 1];
  bk.index.resize(bk.start.back());
  std::vector<std::uint32_t> pos(bk.start.begin(), bk.start.end() - 1);
  for (std::size_t i = 0; i < tris.size(); ++i)
    for (int b = bands.of[tris[i].j0]; b <= bands.of[tris[i].j1]; ++b) bk.index[pos[kind_of(tris[i]) * bands.count + b]++] = static_cast<std::uint32_t>(i);
  return bk;
}

// The triangles voxelize_into maps: those of every object (Scene::objects(): a world-space mesh,
// or an instance whose mesh's triangles go through its transform), and for a solid with holes
// (Treat::Fans) one fan triangle per boundary edge after its own triangles: (b, a, centroid) for
// the boundary edge a -> b, so that every edge of the mesh and its fans is used twice and the
// parity pass sees a closed surface. Closure and hole centroids are per mesh, as an affine map
// keeps both (it maps centroids to centroids).
struct ObjectPlan {
  std::vector<SceneObject> objects;
  std::vector<Holes> holes;              // per mesh of a solid with holes
  std::vector<int> slot_of;              // per object with a hole that is not flat: its slot, else -1
  std::vector<std::size_t> slot_object;  // per slot: the object
  std::vector<std::size_t> first{0};     // object o's triangles are [first[o], first[o + 1])
  std::size_t fanned = 0;                // objects voxelized as solids with holes
};
ObjectPlan plan_objects(const Scene& scene, std::span<const MeshClosure> closure, std::span<const Treat> treat, float voxel) {
  ObjectPlan p;
  p.objects = scene.objects();
  p.holes.resize(scene.meshes.size());
  p.slot_of.assign(p.objects.size(), -1);
  std::vector<std::uint8_t> hole_info(scene.meshes.size(), 0);
  for (std::size_t oi = 0; oi < p.objects.size(); ++oi) {
    const std::size_t mi = p.objects[oi].mesh;
    const bool fans = treat[oi] == Treat::Fans;
    if (fans && !hole_info[mi]) {
      // Two voxels, in the mesh's own units (an instance's scale divides them).
      const float scale = p.objects[oi].instance == SceneObject::kNoInstance
                              ? 1.0f
                              : static_cast<float>(std::cbrt(std::abs(scene.instances[p.objects[oi].instance].object_to_world.determinant())));
      p.holes[mi] = hole_centroids(scene.meshes[mi], closure[mi], 2.0f * voxel / scale), hole_info[mi] = 1;
    }
    if (fans && std::find(p.holes[mi].flat.begin(), p.holes[mi].flat.end(), 0) != p.holes[mi].flat.end()) {
      p.slot_of[oi] = static_cast<int>(p.slot_object.size());
      p.slot_object.push_back(oi);
    }
    p.fanned += fans ? 1 : 0;
    p.first.push_back(p.first.back() + scene.meshes[mi].triangle_count() + (fans ? closure[mi].boundary.size() : 0));
  }
  return p;
}

// Triangle `local` of object `oi` (ObjectPlan) in world space, its slab's side for
// Treat::SlabFlipped; false for a face given a slab that cannot reach `region` (VoxelizeOptions).
bool object_triangle(const Scene& scene, std::span<const MeshClosure> closure, const ObjectPlan& plan, std::span<const Treat> treat, std::size_t oi,
                     std::size_t local, const Bounds3& region, float slab_thickness, Tri3& tri) {
  const std::size_t mi = plan.objects[oi].mesh;
  const Affine3* tf = plan.objects[oi].instance == SceneObject::kNoInstance ? nullptr : &scene.instances[plan.objects[oi].instance].object_to_world;
  const bool open = treat[oi] == Treat::Slab || treat[oi] == Treat::SlabFlipped;
  const Mesh& m = scene.meshes[mi];
  if (local < m.triangle_count()) {
    tri = source_triangle(m, local, open);
    if (open && !region.empty()) {
      Bounds3 reach;  // the triangle and its slab
      for (const Vec3& v : tri.v) reach.extend(tf ? tf->point(v) : v);
      reach.lo -= Vec3{slab_thickness, slab_thickness, slab_thickness};
      reach.hi += Vec3{slab_thickness, slab_thickness, slab_thickness};
      if (reach.hi.x < region.lo.x || reach.lo.x > region.hi.x || reach.hi.y < region.lo.y || reach.lo.y > region.hi.y || reach.hi.z < region.lo.z ||
          reach.lo.z > region.hi.z)
        return false;
    }
    if (plan.slot_of[oi] >= 0 && plan.holes[mi].near[local]) tri.fan = plan.slot_of[oi];
  } else {
    const std::size_t e = local - m.triangle_count();
    const auto [a, b] = closure[mi].boundary[e];
    const std::uint32_t h = closure[mi].hole[e];
    tri = Tri3{{m.positions[b], m.positions[a], plan.holes[mi].centre[h]}, 0, {}, plan.holes[mi].flat[h] ? -1 : plan.slot_of[oi]};
  }
  if (tf) {
    for (Vec3& v : tri.v) v = tf->point(v);
    if (tri.kind == 1) tri.normal = normalize(cross(tri.v[1] - tri.v[0], tri.v[2] - tri.v[0]));
  }
  if (treat[oi] == Treat::SlabFlipped) tri.normal = -tri.normal;
  return true;
}

// The union of one band's prisms (PrismCounts): the voxels where the running count is not 0.
void unite_prisms(VoxelGrid& g, const PrismCounts& counts) {
  for (std::size_t c = 0; c < counts.touched.size(); ++c) {
    if (!counts.touched[c]) continue;
    const std::int16_t* d = counts.delta.get() + c * g.depth_bits;
    std::uint64_t* col = g.bits.data() + (static_cast<std::size_t>(counts.r0) * g.nx + c) * g.words;
    int count = 0;
    for (int v = 0; v < g.depth_bits; ++v) {
      count += d[v];
      if (count != 0) col[v >> 6] |= std::uint64_t{1} << (v & 63);
    }
  }
}

// Rasterises band b's triangles of one fill kind (Buckets; 0: parity, 1: spans, 2: prisms, counted
// and then turned into voxels), listing the fans' fragments in `hits`. Returns fragments.
template <bool kPerspective>
std::size_t raster_band(VoxelGrid& g, const Bands& bands, int b, int fill_kind, const std::vector<std::vector<GridTri>>& tris,
                        const std::vector<Buckets>& buckets, float slab_thickness, std::vector<ColumnHit>& hits) {
  const int r0 = bands.first_row(b), r1 = bands.first_row(b + 1) - 1;
  const std::size_t k = static_cast<std::size_t>(fill_kind) * bands.count + b;
  bool any = false;
  for (std::size_t c = 0; c < buckets.size() && !any; ++c) any = buckets[c].start[k] < buckets[c].start[k + 1];
  if (!any) return 0;
  PrismCounts counts;
  if (fill_kind == 2) {
    const std::size_t columns = static_cast<std::size_t>(r1 - r0 + 1) * g.nx;
    counts = {r0, g.nx, g.depth_bits, std::unique_ptr<std::int16_t[]>(new std::int16_t[columns * g.depth_bits]), std::vector<std::uint8_t>(columns, 0)};
  }
  std::size_t f = 0;
  for (std::size_t c = 0; c < buckets.size(); ++c) {
    const std::uint32_t q0 = buckets[c].start[k], q1 = buckets[c].start[k + 1];
    if (q0 < q1)
      f += simd::rasterise_triangles(tris[c].data(), buckets[c].index.data() + q0, q1 - q0, kPerspective, r0, r1, g, slab_thickness, hits,
                                     fill_kind == 2 ? &counts : nullptr);
  }
  unite_prisms(g, counts);
  return f;
}

// Per slot of a solid with holes (ObjectPlan): object space, sigma (orientation, mirrors
// included) and the winding number of its fans alone (w_C needs no triangle near the point but
// the fans' own, unlike w of the mesh).
struct SlotWinding {
  std::vector<ObjectSpace> space;
  std::vector<int> sign;
  std::vector<FanWinding> fans;
};
SlotWinding slot_winding(const Scene& scene, std::span<const MeshClosure> closure, const ObjectPlan& plan) {
  SlotWinding s;
  for (std::size_t oi : plan.slot_object) {
    const std::size_t mi = plan.objects[oi].mesh;
    s.space.push_back(object_space(scene, plan.objects[oi]));
    s.sign.push_back(closure[mi].orientation * s.space.back().sign);
    s.fans.push_back(fan_winding(scene.meshes[mi], closure[mi], plan.holes[mi]));
  }
  return s;
}

// Voxels where w was evaluated, and of those, where it changed the parity's answer; and one
// band's scratch space.
struct WalkCount {
  std::size_t evaluated = 0, changed = 0;
};
struct WalkScratch {
  std::vector<std::uint64_t> chi, seen;
  std::vector<Vec3> r;
  std::vector<float> len;
};

// Walks the column of list[q] from each of its fragments of the same slot (sorted together),
// both ways, setting each voxel to [sigma w(centre) > 1/2] until that agrees with parity (see
// winding_solid). chi is the column as parity left it, so each voxel is decided once however many
// walks reach it. Returns the index past those fragments.
template <class Centre>
std::size_t walk_column(VoxelGrid& g, const std::vector<ColumnHit>& list, std::size_t q, const SlotWinding& sw, Centre& voxel_centre, WalkScratch& sc,
                        WalkCount& n) {
  std::vector<std::uint64_t>& chi = sc.chi;
  std::vector<std::uint64_t>& seen = sc.seen;
  const ColumnHit& at = list[q];
  std::uint64_t* col = g.bits.data() + (static_cast<std::size_t>(at.j) * g.nx + at.i) * g.words;
  chi.assign(col, col + g.words);
  seen.assign(g.words, 0);
  const int s = at.tag;
  for (; q < list.size() && list[q].i == at.i && list[q].j == at.j && list[q].tag == s; ++q)
    for (int dir : {1, -1})
      for (int k = dir > 0 ? list[q].k : list[q].k - 1; k >= 0 && k < g.depth_bits; k += dir) {
        const std::uint64_t bit = std::uint64_t{1} << (k & 63);
        const bool parity = (chi[k >> 6] & bit) != 0;
        bool solid;
        if (seen[k >> 6] & bit) {
          solid = (col[k >> 6] & bit) != 0;
        } else {
          // w = chi - w_C: solid where sigma w = chi - sigma w_C > 1/2.
          solid = (parity ? 1.0 : 0.0) - sw.sign[s] * sw.fans[s](sw.space[s](voxel_centre(at.i, at.j, k)), sc.r, sc.len) > 0.5;
          seen[k >> 6] |= bit;
          ++n.evaluated;
          if (solid != parity) col[k >> 6] ^= bit, ++n.changed;
        }
        if (solid == parity) break;
      }
  return q;
}

// The winding-number solid near holes that are not flat. Parity with the fans is the solid chi
// of the mesh plus its fans C; the mesh's own winding number is w = chi - w_C (w is a sum over
// triangles; sigma w with sigma the orientation, voxelize.h), and the solid is w > 1/2. The two
// differ only where |w_C| >= 1/2, which is next to a fan that is not flat: in the pocket between
// the fan and the surface w = 1/2 that spans the hole, which the mesh itself can also cut near
// the hole's rim. Along a column the pocket is entered through the fan or through the mesh near
// the hole (it is bounded by them and that surface), so from each such fragment (`hits`, per
// band) we walk the column both ways and stop at the first voxel where w agrees with parity: the
// pocket's end. (A column that crossed the spanning surface twice and neither the fan nor the
// mesh would be missed.)
template <class Centre>
WalkCount winding_solid(VoxelGrid& g, std::vector<std::vector<ColumnHit>>& hits, const SlotWinding& sw, Centre& voxel_centre) {
  std::vector<WalkCount> in(hits.size());
  tbb::parallel_for(0, static_cast<int>(hits.size()), [&](int b) {
    std::vector<ColumnHit>& list = hits[b];
    std::sort(list.begin(), list.end(), [](const ColumnHit& x, const ColumnHit& y) { return std::tie(x.j, x.i, x.tag, x.k) < std::tie(y.j, y.i, y.tag, y.k); });
    WalkScratch scratch;
    for (std::size_t q = 0; q < list.size();) q = walk_column(g, list, q, sw, voxel_centre, scratch, in[b]);
  });
  WalkCount n;
  for (const WalkCount& w : in) n.evaluated += w.evaluated, n.changed += w.changed;
  return n;
}

VoxelStats grid_stats(const std::vector<std::vector<GridTri>>& tris, std::span<const std::size_t> fragments, std::span<const MeshClosure> closure) {
  VoxelStats s;
  for (const auto& chunk : tris) s.triangles += chunk.size();
  for (std::size_t f : fragments) s.fragments += f;
  for (const MeshClosure& c : closure) {
    s.open_meshes += c.open_surface() ? 1 : 0;
    s.holed_meshes += c.holed() ? 1 : 0;
    s.holes += c.holed() ? c.holes : 0;
    s.boundary_edges += c.boundary_edges;
  }
  return s;
}

// The rooms among the objects voxelized by parity (VoxelizeOptions::rooms).
std::size_t rooms_by_parity(const VoxelizeOptions& o, std::span<const Treat> treat) {
  if (o.open_meshes == OpenMeshes::Parity) return 0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < std::min(o.rooms.size(), treat.size()); ++k) n += o.rooms[k] && treat[k] == Treat::Parity ? 1 : 0;
  return n;
}

// Complements every column's depth_bits voxels (the bits past them stay clear).
void complement_columns(VoxelGrid& g) {
  const std::size_t columns = static_cast<std::size_t>(g.nx) * g.ny;
  const int tail = g.depth_bits % 64;
  const std::uint64_t last = tail ? (std::uint64_t{1} << tail) - 1 : ~std::uint64_t{0};
  tbb::parallel_for(std::size_t{0}, columns, [&](std::size_t c) {
    std::uint64_t* col = &g.bits[c * static_cast<std::size_t>(g.words)];
    for (int w = 0; w < g.words; ++w) col[w] = ~col[w] & (w == g.words - 1 ? last : ~std::uint64_t{0});
  });
}

// Stages 1-4 for any grid whose geometry fields are set; `voxel` is the largest extent of a voxel
// (world units), `emit` maps one Tri3 into a vector, `voxel_centre(i, j, k)` gives the world point
// of a voxel's centre.
template <bool kPerspective, class Emit, class Centre>
void voxelize_into(VoxelGrid& g, const Scene& scene, std::span<const MeshClosure> closure, const VoxelizeOptions& o, const Treatments& treatment,
                   float slab_thickness, float voxel, Emit&& emit, Centre&& voxel_centre, VoxelStats* stats) {
  const std::span<const Treat> treat = treatment.of;
  g.depth_bits = o.depth_bits;
  g.words = (o.depth_bits + 63) / 64;
  g.bits.assign(static_cast<std::size_t>(g.nx) * g.ny * g.words, 0);

  // 1. Map triangles to the grid, chunk by chunk (chunk boundaries are fixed: deterministic),
  // and bucket each chunk's triangles by (fill kind, row band) so that a band visits only the
  // triangles overlapping it.
  const Bands bands = make_bands(g.ny);
  const ObjectPlan plan = plan_objects(scene, closure, treat, voxel);
  const std::size_t total = plan.first.back();
  const std::size_t chunks = (total + kChunk - 1) / kChunk;
  std::vector<std::vector<GridTri>> tris(chunks);
  std::vector<Buckets> buckets(chunks);
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
    const std::size_t t0 = c * kChunk, t1 = std::min(total, t0 + kChunk);
    std::size_t oi = static_cast<std::size_t>(std::upper_bound(plan.first.begin(), plan.first.end(), t0) - plan.first.begin()) - 1;
    auto& out = tris[c];
    out.reserve(t1 - t0);
    for (std::size_t t = t0; t < t1; ++t) {
      while (t >= plan.first[oi + 1]) ++oi;
      Tri3 tri;
      if (object_triangle(scene, closure, plan, treat, oi, t - plan.first[oi], o.slab_region, slab_thickness, tri)) emit(out, tri);
    }
    buckets[c] = bucket(out, bands);
  });

  // 2. Raster bands of rows; parity fragments first, then (after the scan) open-mesh slabs,
  // which are ORed: a union, so overlapping slabs of neighbouring open triangles do not cancel.
  std::vector<std::size_t> fragments(bands.count, 0);
  std::vector<std::vector<ColumnHit>> hits(bands.count);  // fans' fragments (pass 0)
  const auto raster_pass = [&](int fill_kind) {
    tbb::parallel_for(0, bands.count, [&](int b) { fragments[b] += raster_band<kPerspective>(g, bands, b, fill_kind, tris, buckets, slab_thickness, hits[b]); });
  };
  raster_pass(0);

  // 3. Toggles -> solid, then the winding-number solid near holes that are not flat.
  const std::size_t odd = scan_columns(g);
  const WalkCount walked = plan.slot_object.empty() ? WalkCount{} : winding_solid(g, hits, slot_winding(scene, closure, plan), voxel_centre);

  // A closed mesh around the camera (a room) encloses air: its solid is the complement of its
  // parity (but for open_meshes=parity, the paper's voxelization of everything as it is). The
  // world grid's columns start outside every mesh, so with an odd number of rooms the whole grid
  // is complemented (objects inside the room stay solid: they toggle back). An eye grid's columns
  // start at the camera, inside the room, where parity is already right.
  if constexpr (!kPerspective) {
    if (rooms_by_parity(o, treat) % 2) complement_columns(g);
  }

  // 4. Slabs of open meshes, ORed after the parity; walls' prisms as the union of the prisms: per
  // column, the voxels where the count of prisms entered minus left is not 0 (prisms overlap
  // where walls meet, and parity would cancel them there).
  if (any_slab(treat)) {
    raster_pass(1);
    raster_pass(2);
  }
  const std::size_t set_voxels = build_coarse(g);  // also counts the solid voxels
  if (stats) {
    *stats = grid_stats(tris, fragments, closure);
    stats->odd_columns = odd;
    stats->set_voxels = set_voxels;
    stats->capped_meshes = plan.fanned;
    stats->back_objects = treatment.back;
    stats->winding_evaluations = walked.evaluated;
    stats->winding_voxels_changed = walked.changed;
  }
}

}  // namespace

void VoxelizeOptions::validate() const {
  if (columns < 8 || columns > 4096) throw InputError("cone: columns must be in [8, 4096], got " + std::to_string(columns));
  if (depth_bits < 32 || depth_bits > 1024 || depth_bits % 32 != 0)
    throw InputError("cone: depth_bits must be a multiple of 32 in [32, 1024], got " + std::to_string(depth_bits));
  if (!(slab_thickness >= 0.0f) || !std::isfinite(slab_thickness))
    throw InputError("cone: slab thickness must be a finite number >= 0, got " + std::to_string(slab_thickness));
}

std::size_t VoxelGrid::count_set() const {
  return simd::count_set_bits(bits.data(), bits.size());
}

namespace {

// Sheet or solid with holes, from the winding number of the mesh itself (voxelize.h, MeshKind).
// Just in front of and just behind a triangle's centroid c, w(c + n d) + w(c - n d) = 2 w_rest(c):
// the triangle's own solid angles cancel (mirror images), leaving twice the winding number of
// the rest of the mesh at c. A closed mesh has w_rest = 1/2 everywhere (the rest subtends the
// whole half-space behind the face), a flat sheet 0. `enclosure` is the magnitude of 2 w_rest
// averaged over the area (at every (n / kEnclosureSamples)-th triangle), `orientation` its sign.
void classify_open_mesh(const Mesh& m, MeshClosure& c) {
  c.winding = MeshWinding(m);
  const std::size_t nt = m.triangle_count();
  // Small holes (kSmallHoles): each hole's vector area from its boundary edges (about any point,
  // here its first vertex), the orientation from the sign of the enclosed volume (about the box's
  // centre; the holes change it little).
  {
    std::vector<Vec3> hole_area(c.holes, Vec3{0, 0, 0}), origin(c.holes, Vec3{0, 0, 0});
    std::vector<std::uint8_t> has(c.holes, 0);
    for (std::size_t e = 0; e < c.boundary.size(); ++e) {
      const std::uint32_t h = c.hole[e];
      if (!has[h]) origin[h] = m.positions[c.boundary[e][0]], has[h] = 1;
      hole_area[h] += cross(m.positions[c.boundary[e][0]] - origin[h], m.positions[c.boundary[e][1]] - origin[h]) * 0.5f;
    }
    double holes = 0, area = 0, volume = 0;
    for (const Vec3& a : hole_area) holes += length(a);
    const Vec3 o = m.bounds().center();
    for (std::size_t t = 0; t < nt; ++t) {
      const Vec3 a = m.positions[m.indices[3 * t]] - o, b = m.positions[m.indices[3 * t + 1]] - o, d = m.positions[m.indices[3 * t + 2]] - o;
      area += 0.5 * length(cross(b - a, d - a));
      volume += dot(a, cross(b, d)) / 6.0;
    }
    if (area > 0 && holes < kSmallHoles * area) {
      c.kind = MeshKind::SolidWithHoles;
      c.enclosure = static_cast<float>(1.0 - holes / area);
      c.orientation = volume < 0 ? -1 : 1;
      return;
    }
  }
  const std::size_t step = std::max<std::size_t>(1, nt / kEnclosureSamples);
  double sum = 0, area = 0;
  Vec3 vector_area{0, 0, 0};
  for (std::size_t t = 0; t < nt; ++t) {
    const Vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]], d = m.positions[m.indices[3 * t + 2]];
    vector_area += cross(b - a, d - a) * 0.5f;
  }
  for (std::size_t t = 0; t < nt; t += step) {
    const Vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]], d = m.positions[m.indices[3 * t + 2]];
    const Vec3 n2 = cross(b - a, d - a);
    const float len = length(n2);
    if (!(len > 0.0f)) continue;
    const float at = 0.5f * len;
    // 1% of the inradius (2 area / perimeter): far closer to c than any other triangle is.
    const float delta = 0.01f * 2.0f * at / (length(b - a) + length(d - b) + length(a - d));
    const Vec3 centre = (a + b + d) * (1.0f / 3.0f), n = n2 / len;
    sum += at * (c.winding.get()(centre + n * delta) + c.winding.get()(centre - n * delta));
    area += at;
  }
  const double mean = area > 0 ? sum / area : 0.0;
  c.enclosure = static_cast<float>(std::min(1.0, std::abs(mean)));
  c.orientation = mean < 0 ? -1 : 1;
  c.kind = c.enclosure >= kSolidEnclosure ? MeshKind::SolidWithHoles : MeshKind::Sheet;
  // A flat sheet (a ground, a wall): every vertex within 1e-5 of its extent of one plane. Its
  // winding number then has the sign of the side of that plane everywhere.
  const float len = length(vector_area);
  if (len > 0.0f) {
    const Vec3 n = vector_area / len;
    const Bounds3 box = m.bounds();
    const float tol = 1e-5f * box.diagonal();
    const float offset = dot(n, m.positions[m.indices[0]]);
    bool flat = true;
    for (std::uint32_t i : m.indices) flat = flat && std::abs(dot(n, m.positions[i]) - offset) <= tol;
    if (flat) c.plane = {n.x, n.y, n.z, -offset};
    c.flat = flat;
  }
}

}  // namespace

struct MeshWinding::State {
  const Mesh* mesh = nullptr;
  std::once_flag once;
  std::unique_ptr<WindingNumber> field;
};

MeshWinding::MeshWinding(const Mesh& mesh) : state_(std::make_shared<State>()) { state_->mesh = &mesh; }

const WindingNumber& MeshWinding::get() const {
  static const WindingNumber empty;
  if (!state_) return empty;
  std::call_once(state_->once, [&] { state_->field = std::make_unique<WindingNumber>(state_->mesh->positions, state_->mesh->indices); });
  return *state_->field;
}

std::vector<MeshClosure> analyze_closure(const Scene& scene) {
  std::vector<MeshClosure> out;
  out.reserve(scene.meshes.size());
  for (const Mesh& m : scene.meshes) {
    // Weld vertices by exact position, then count each undirected edge; an edge used an odd
    // number of times is a boundary (a closed 2-manifold uses each edge twice).
    const std::size_t nv = m.positions.size();
    std::vector<std::pair<std::array<std::uint32_t, 3>, std::uint32_t>> keyed(nv);
    for (std::size_t v = 0; v < nv; ++v) {
      std::array<std::uint32_t, 3> k;
      const float c[3] = {m.positions[v].x + 0.0f, m.positions[v].y + 0.0f, m.positions[v].z + 0.0f};  // + 0 turns -0 into +0
      std::memcpy(k.data(), c, sizeof c);
      keyed[v] = {k, static_cast<std::uint32_t>(v)};
    }
    std::sort(keyed.begin(), keyed.end());
    std::vector<std::uint32_t> id(nv);
    std::uint32_t next = 0;
    for (std::size_t v = 0; v < nv; ++v) {
      if (v > 0 && keyed[v].first != keyed[v - 1].first) ++next;
      id[keyed[v].second] = next;
    }
    // (undirected key, directed edge index 3 t + e) so that a boundary edge keeps its direction.
    std::vector<std::pair<std::uint64_t, std::uint32_t>> edges;
    edges.reserve(m.indices.size());
    for (std::size_t t = 0; t < m.triangle_count(); ++t)
      for (int e = 0; e < 3; ++e) {
        std::uint64_t a = id[m.indices[3 * t + e]], b = id[m.indices[3 * t + (e + 1) % 3]];
        if (a > b) std::swap(a, b);
        edges.push_back({a << 32 | b, static_cast<std::uint32_t>(3 * t + e)});
      }
    std::sort(edges.begin(), edges.end());
    MeshClosure c;
    for (std::size_t i = 0; i < edges.size();) {
      std::size_t j = i;
      while (j < edges.size() && edges[j].first == edges[i].first) ++j;
      if ((j - i) % 2) {
        const std::uint32_t de = edges[i].second, t = de / 3, e = de % 3;
        c.boundary.push_back({m.indices[3 * t + e], m.indices[3 * t + (e + 1) % 3]});
      }
      ++c.edges;
      i = j;
    }
    c.boundary_edges = c.boundary.size();
    if (!c.boundary.empty()) {
      // Holes: connected components of the boundary edges over welded vertices (union-find).
      std::vector<std::uint32_t> parent(next + 1);
      for (std::uint32_t v = 0; v <= next; ++v) parent[v] = v;
      const auto find = [&](std::uint32_t v) {
        while (parent[v] != v) v = parent[v] = parent[parent[v]];
        return v;
      };
      for (const auto& [a, b] : c.boundary) parent[find(id[a])] = find(id[b]);
      std::vector<std::uint32_t> number(next + 1, ~0u);
      for (const auto& [a, b] : c.boundary) {
        std::uint32_t& n = number[find(id[a])];
        if (n == ~0u) n = c.holes++;
        c.hole.push_back(n);
      }
      classify_open_mesh(m, c);
    }
    out.push_back(std::move(c));
  }
  return out;
}

std::vector<std::uint8_t> closed_meshes_around(const Scene& scene, std::span<const MeshClosure> closure, Vec3 eye) {
  const std::vector<SceneObject> objects = scene.objects();
  std::vector<std::uint8_t> around(objects.size(), 0);
  bool any = false;
  // A direction no axis-aligned or diagonal face contains, so the ray meets no edge of a modelled
  // room exactly.
  const Vec3 dir = normalize(Vec3{0.5734f, 0.6321f, 0.5213f});
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const Mesh& m = scene.meshes[objects[k].mesh];
    if (!closure[objects[k].mesh].closed()) continue;
    // The eye and the ray in the mesh's own space.
    Vec3 p = eye, d = dir;
    if (objects[k].instance != SceneObject::kNoInstance) {
      const Affine3 to_object = inverse(scene.instances[objects[k].instance].object_to_world);
      p = to_object.point(eye), d = to_object.vector(dir);
    }
    const Bounds3 b = m.bounds();
    if (p.x < b.lo.x || p.y < b.lo.y || p.z < b.lo.z || p.x > b.hi.x || p.y > b.hi.y || p.z > b.hi.z) continue;
    std::size_t crossings = 0;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      // Moller-Trumbore: the ray p + s d, s > 0, through the triangle.
      const Vec3 a = m.positions[m.indices[3 * t]], e1 = m.positions[m.indices[3 * t + 1]] - a, e2 = m.positions[m.indices[3 * t + 2]] - a;
      const Vec3 h = cross(d, e2);
      const float det = dot(e1, h);
      if (det == 0.0f) continue;
      const float inv = 1.0f / det;
      const Vec3 q = p - a;
      const float u = dot(q, h) * inv;
      if (u < 0.0f || u > 1.0f) continue;
      const Vec3 r = cross(q, e1);
      const float v = dot(d, r) * inv;
      if (v < 0.0f || u + v > 1.0f) continue;
      crossings += dot(e2, r) * inv > 0.0f ? 1 : 0;
    }
    around[k] = crossings % 2;
    any = any || around[k];
  }
  if (!any) around.clear();
  return around;
}

VoxelGrid voxelize_world(const Scene& scene, std::span<const MeshClosure> closure, const VoxelizeOptions& o, VoxelStats* stats,
                         std::span<const std::uint8_t> back) {
  o.validate();
  const Treatments treat = treatments(scene, closure, o.open_meshes, back);
  VoxelGrid g;
  g.space = GridSpace::World;
  g.nx = g.ny = o.columns;
  const Bounds3 b = scene.bounds();
  if (b.empty()) throw InputError(scene.name + ": cannot voxelize an empty scene");
  // A flat scene has no height: give every axis at least 1e-4 of the diagonal so voxels have size.
  const float floor_extent = std::max(1e-4f * b.diagonal(), 1e-6f);
  const Vec3 e = max(b.extent(), Vec3{floor_extent, floor_extent, floor_extent});
  const float v0 = std::max({e.x / o.columns, e.z / o.columns, e.y / o.depth_bits});
  const float slab = o.slab_thickness > 0 ? o.slab_thickness : 2.0f * v0;
  // One voxel of margin on every side, and room for the slabs of open meshes below and beside
  // (a ground plane's slab hangs below it, a wall's prism stands behind it), and above when a
  // slab rises from a face (a roof seen from below, a ceiling seen from the room). A room (a
  // closed mesh around the camera) is solid outside: a slab's thickness of it all around, so that
  // a cone near its walls meets as much solid as behind an open wall.
  const bool room = rooms_by_parity(o, treat.of) > 0;
  const float side = (any_slab(treat.of) || room ? slab : 0.0f) + v0;
  const float top = (slab_rises(scene, treat.of) || room ? slab : 0.0f) + v0;
  const Vec3 lo = b.lo - Vec3{side, side, side};
  const Vec3 ext = e + Vec3{2 * side, side + top, 2 * side};
  g.origin = lo;
  g.voxel_size = {ext.x / o.columns, ext.z / o.columns, ext.y / o.depth_bits};
  const WorldMap map{lo, {1.0f / g.voxel_size.x, 1.0f / g.voxel_size.y, 1.0f / g.voxel_size.z}, slab};
  const Vec3 origin = g.origin, size = g.voxel_size;
  voxelize_into<false>(
      g, scene, closure, o, treat, slab, std::max({g.voxel_size.x, g.voxel_size.y, g.voxel_size.z}), [&](std::vector<GridTri>& out, const Tri3& t) { emit_world(out, t, map, g.nx, g.ny); },
      [origin, size](int i, int j, int k) {
        return Vec3{origin.x + (static_cast<float>(i) + 0.5f) * size.x, origin.y + (static_cast<float>(k) + 0.5f) * size.z,
                    origin.z + (static_cast<float>(j) + 0.5f) * size.y};
      },
      stats);
  return g;
}

namespace {

// z_nearest per column of an eye grid whose camera, columns and z_far are set: the smallest
// G-buffer depth among the pixels whose centres it holds (eq. 2's local slice); columns that see no
// surface use `zmin`, the scene's nearest corner. Then the voxels per unit depth of each column.
void set_z_near(VoxelGrid& g, const GBuffer& gb, float zmin, float z_clip, int depth_bits) {
  const std::size_t ncol = static_cast<std::size_t>(g.nx) * g.ny;
  g.z_near.assign(ncol, kInfinity);
  for (int y = 0; y < g.camera.height; ++y) {
    const int j = std::min(g.ny - 1, static_cast<int>((y + 0.5f) / g.pixels_per_column_y));
    for (int x = 0; x < g.camera.width; ++x) {
      if (!gb.covered(x, y)) continue;
      const int i = std::min(g.nx - 1, static_cast<int>((x + 0.5f) / g.pixels_per_column_x));
      float& zn = g.z_near[static_cast<std::size_t>(j) * g.nx + i];
      zn = std::min(zn, gb.depth(x, y));
    }
  }
  g.voxels_per_unit.resize(ncol);
  for (std::size_t c = 0; c < ncol; ++c) {
    float& zn = g.z_near[c];
    if (!std::isfinite(zn)) zn = zmin;
    zn = std::clamp(zn, z_clip, g.z_far * 0.999f);
    g.voxels_per_unit[c] = static_cast<float>(depth_bits) / (g.z_far - zn);
  }
}

}  // namespace

VoxelGrid voxelize_eye(const Scene& scene, std::span<const MeshClosure> closure, const GBuffer& gb, const VoxelizeOptions& o, VoxelStats* stats,
                       std::span<const std::uint8_t> back) {
  o.validate();
  const Treatments treat = treatments(scene, closure, o.open_meshes, back);
  VoxelGrid g;
  g.space = GridSpace::Eye;
  const Camera& cam = gb.camera;
  const int W = cam.width, H = cam.height;
  if (W >= H) {
    g.nx = o.columns;
    g.ny = std::max(1, static_cast<int>(std::lround(static_cast<double>(o.columns) * H / W)));
  } else {
    g.ny = o.columns;
    g.nx = std::max(1, static_cast<int>(std::lround(static_cast<double>(o.columns) * W / H)));
  }
  g.camera = cam;
  g.pixels_per_column_x = static_cast<float>(W) / g.nx;
  g.pixels_per_column_y = static_cast<float>(H) / g.ny;

  const Bounds3 b = scene.bounds();
  if (b.empty()) throw InputError(scene.name + ": cannot voxelize an empty scene");
  const Frame basis = cam.basis();
  float zmin = kInfinity, zmax = 0;
  for (int c = 0; c < 8; ++c) {
    const Vec3 p{c & 1 ? b.hi.x : b.lo.x, c & 2 ? b.hi.y : b.lo.y, c & 4 ? b.hi.z : b.lo.z};
    const float d = -basis.to_local(p - cam.eye).z;
    zmin = std::min(zmin, d);
    zmax = std::max(zmax, d);
  }
  const float diag = b.diagonal();
  // Near clipping plane: 1e-4 of the scene diagonal in front of the eye, far enough from 0 for
  // 1/depth to stay finite, close enough that only geometry touching the eye is lost.
  const float z_clip = std::max(1e-4f * diag, 1e-6f);
  zmin = std::max(zmin, z_clip);
  // The slab extends behind the far corner too, and by one voxel so the last fragment fits.
  const float column_at_far = 2.0f * cam.tan_half_fov() * std::max(zmax, z_clip) / g.ny;
  const float v0 = std::max(column_at_far, (zmax - zmin) / o.depth_bits);
  const float slab = o.slab_thickness > 0 ? o.slab_thickness : 2.0f * v0;
  g.z_far = std::max(zmax + slab + v0, zmin * 2.0f);

  set_z_near(g, gb, zmin, z_clip, o.depth_bits);

  // Camera-space (x, y, depth) -> column: camera.project divided by the pixels per column.
  const float t = cam.tan_half_fov();
  EyeMap map;
  map.basis = basis;
  map.eye = cam.eye;
  map.sx = 0.5f * W / (t * cam.aspect()) / g.pixels_per_column_x;
  map.ox = 0.5f * W / g.pixels_per_column_x;
  map.sy = -0.5f * H / t / g.pixels_per_column_y;
  map.oy = 0.5f * H / g.pixels_per_column_y;
  map.z_clip = z_clip;
  map.slab = slab;
  // The inverse of eq. 2 and of the projection: column (i, j)'s centre is the view ray through
  // ((i + 0.5 - ox) / sx, (j + 0.5 - oy) / sy) per unit depth, voxel k at depth z_near + (k + 0.5) / vpu.
  const auto centre = [&g, &map](int i, int j, int k) {
    const std::size_t c = static_cast<std::size_t>(j) * g.nx + i;
    const float depth = g.z_near[c] + (static_cast<float>(k) + 0.5f) / g.voxels_per_unit[c];
    const Vec3 local{(static_cast<float>(i) + 0.5f - map.ox) / map.sx * depth, (static_cast<float>(j) + 0.5f - map.oy) / map.sy * depth, -depth};
    return map.eye + map.basis.to_world(local);
  };
  voxelize_into<true>(
      g, scene, closure, o, treat, slab, v0, [&](std::vector<GridTri>& out, const Tri3& tri) { emit_eye(out, tri, map, g.nx, g.ny); }, centre, stats);
  return g;
}

}  // namespace ao
