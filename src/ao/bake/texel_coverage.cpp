// SPDX-License-Identifier: Apache-2.0
// Exact UV coverage of the texel grid. Each triangle is clipped (Sutherland-Hodgman) against every
// texel square its UV bounding box touches, column by column: to the column's two lines once, then
// that polygon to the two lines of each row it reaches (the clips clip_to_texel makes, in its
// order); the clipped area, scaled by the triangle's ratio of world area to UV area (constant over
// a triangle, since the parameterisation is linear there: the paper's sec. 3, after eq. 3), is
// that texel's share of surface. Summing these shares gives
// the exact denominator of eq. 2/3 without the paper's assumption that stretch is constant over a
// texel (eq. 4), which fails at chart borders and where triangles of different stretch meet.
#include "ao/bake/texel_coverage.h"

#include <algorithm>
#include <cmath>
#include <span>

#include <tbb/parallel_for.h>

#include "ao/core/error.h"

namespace ao {

namespace {

constexpr int kMaxSize = 16384;
constexpr std::size_t kBlock = 4096;  // triangles per parallel block (blocks are merged in order)
constexpr int kBandRows = 16;         // texel rows per band of the parallel merge
int band_count(int height) { return (height + kBandRows - 1) / kBandRows; }
// A UV triangle smaller than this many texels^2 per world unit^2 of surface, relative to the
// map, counts as degenerate: its texels would get a weight 1e6 times the average.
constexpr double kDegenerateRatio = 1e-6;

struct Pending {
  std::uint32_t texel;
  TexelFragment frag;
};

// A polygon being clipped: plain corners, so that the buffers of each step are not zeroed first.
struct Corner {
  float x, y;
};

// The corners of in[0 .. n) on the kept side of the line coordinate[kAxis] = bound (>= bound when
// kKeepGreater, else <=) into out, in order; returns their count. A corner exactly on the line is
// kept; where an edge crosses the line, the crossing, its coordinate along kAxis set to the bound.
template <int kAxis, bool kKeepGreater>
int clip_half_plane(const Corner* in, int n, float bound, Corner* out) {
  const auto coord = [](Corner p) { return kAxis == 0 ? p.x : p.y; };
  const auto inside = [&](Corner p) { return kKeepGreater ? coord(p) >= bound : coord(p) <= bound; };
  int m = 0;
  for (int i = 0; i < n; ++i) {
    const Corner a = in[i], b = in[i + 1 == n ? 0 : i + 1];
    const bool ia = inside(a), ib = inside(b);
    if (ia) out[m++] = a;
    if (ia != ib) {
      const float ca = coord(a), cb = coord(b);
      const float t = (bound - ca) / (cb - ca);
      Corner q{a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)};
      if (kAxis == 0) q.x = bound;
      else q.y = bound;
      out[m++] = q;
    }
  }
  return m;
}

}  // namespace

float ClipPolygon::area() const {
  double s = 0;
  for (int i = 0; i < n; ++i) {
    const Vec2 a = p[i], b = p[(i + 1) % n];
    s += static_cast<double>(a.x) * b.y - static_cast<double>(b.x) * a.y;
  }
  return static_cast<float>(std::abs(s) * 0.5);
}

namespace {

// A convex polygon being clipped, in two buffers that the clips alternate between.
struct ClipBuffers {
  Corner buf[2][9];
  int n = 0, cur = 0;
  const Corner* corners() const { return buf[cur]; }
  // The clip against one line. A clip whose line keeps every corner would copy the polygon as it
  // is, so it is skipped (a triangle in a texel's interior needs no clip at all).
  template <int kAxis, bool kKeepGreater>
  void clip(float bound) {
    bool all_in = true;
    for (int i = 0; i < n; ++i) {
      const float v = kAxis == 0 ? buf[cur][i].x : buf[cur][i].y;
      all_in = all_in && (kKeepGreater ? v >= bound : v <= bound);
    }
    if (all_in) return;
    n = clip_half_plane<kAxis, kKeepGreater>(buf[cur], n, bound, buf[1 - cur]);
    cur = 1 - cur;
  }
};

// Triangle a b c clipped to the column x <= u <= x + 1: the first two of clip_to_texel's four
// clips, the same for every texel of the column.
ClipBuffers clip_to_column(Vec2 a, Vec2 b, Vec2 c, int x) {
  ClipBuffers col;
  col.buf[0][0] = {a.x, a.y}, col.buf[0][1] = {b.x, b.y}, col.buf[0][2] = {c.x, c.y};
  col.n = 3;
  col.clip<0, true>(static_cast<float>(x));
  col.clip<0, false>(static_cast<float>(x + 1));
  return col;
}

// A column's polygon clipped to the row y <= v <= y + 1: clip_to_texel's last two clips.
ClipPolygon clip_to_row(const ClipBuffers& column, int y) {
  ClipBuffers cell;
  cell.n = column.n;
  std::copy_n(column.corners(), column.n, cell.buf[0]);
  cell.clip<1, true>(static_cast<float>(y));
  cell.clip<1, false>(static_cast<float>(y + 1));
  ClipPolygon poly;
  poly.n = cell.n;
  for (int i = 0; i < cell.n; ++i) poly.p[i] = {cell.corners()[i].x, cell.corners()[i].y};
  return poly;
}

}  // namespace

ClipPolygon clip_to_texel(Vec2 a, Vec2 b, Vec2 c, int x, int y) { return clip_to_row(clip_to_column(a, b, c, x), y); }

std::vector<std::string> TexelCoverage::warnings() const {
  std::vector<std::string> w;
  if (overlapping_texels > 0)
    w.push_back(std::to_string(overlapping_texels) + " texels are covered by overlapping UV charts; they get the area-weighted mean of the surfaces that share them");
  if (degenerate_uv_triangles > 0)
    w.push_back(std::to_string(degenerate_uv_triangles) + " triangles have (near) zero UV area and get no texels");
  if (outside_triangles > 0)
    w.push_back(std::to_string(outside_triangles) + " triangles reach outside the UV square [0,1]^2; the part outside is not baked");
  return w;
}

TexelCoverage compute_texel_coverage(const Scene& scene, int size) { return compute_texel_coverage(scene, size, size); }

void require_no_instances(const Scene& scene) {
  if (!scene.instances.empty())
    throw InputError(scene.name + ": has " + std::to_string(scene.instances.size()) +
                     " mesh instances; baking needs every placed mesh as a copy of its own (load it with flatten_instances)");
}

namespace {

// A triangle in texel units: its UV corners, its world area and its UV area (texels^2).
struct TexelTriangle {
  Vec2 a, b, c;
  double world = 0, uv = 0;
};

TexelTriangle texel_triangle(const Mesh& m, std::size_t t, int width, int height) {
  const std::uint32_t* i = &m.indices[3 * t];
  TexelTriangle tri;
  tri.world = length(cross(m.positions[i[1]] - m.positions[i[0]], m.positions[i[2]] - m.positions[i[0]])) * 0.5;
  tri.a = texel_uv(m, i[0], width, height), tri.b = texel_uv(m, i[1], width, height), tri.c = texel_uv(m, i[2], width, height);
  const Vec2 a = tri.a, b = tri.b, c = tri.c;
  tri.uv = std::abs((static_cast<double>(b.x) - a.x) * (c.y - a.y) - (static_cast<double>(c.x) - a.x) * (b.y - a.y)) * 0.5;
  return tri;
}

// The map's texels^2 per world unit^2 over every triangle with UVs: the scale of the relative
// degeneracy test. Throws when no mesh has UVs or every UV triangle is flat.
double mean_texel_ratio(const Scene& scene, int width, int height) {
  double total_world = 0, total_uv = 0;
  bool any_uv = false;
  for (const Mesh& m : scene.meshes) {
    if (m.uvs.empty()) continue;
    any_uv = true;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      const TexelTriangle tri = texel_triangle(m, t, width, height);
      total_world += tri.world;
      total_uv += tri.uv;
    }
  }
  if (!any_uv) throw InputError(scene.name + ": the mesh has no UV coordinates; bake per-vertex AO with --per-vertex out.ply instead");
  if (!(total_uv > 0)) throw InputError(scene.name + ": every triangle has zero UV area (all UVs coincide); the UV layout is unusable");
  return total_uv / std::max(total_world, 1e-300);
}

// A run of triangles of one mesh, clipped by one task; the runs are merged in order.
struct Block {
  std::uint32_t mesh;
  std::size_t first, last;
  std::vector<Pending> pending;  // the run's fragments by band of texel rows, within a band in triangle then texel order
  std::vector<std::size_t> band_start;  // band b's fragments are pending[band_start[b] .. band_start[b + 1])
  std::size_t degenerate = 0, outside = 0;
};

// Sorts blk's fragments by band of texel rows, stably (a counting sort), for gather_by_texel.
void by_band(int width, int height, Block& blk) {
  const auto band = [&](const Pending& p) { return static_cast<std::size_t>(p.texel / static_cast<std::uint32_t>(width)) / kBandRows; };
  blk.band_start.assign(static_cast<std::size_t>(band_count(height)) + 1, 0);
  for (const Pending& p : blk.pending) ++blk.band_start[band(p) + 1];
  for (std::size_t b = 1; b < blk.band_start.size(); ++b) blk.band_start[b] += blk.band_start[b - 1];
  std::vector<std::size_t> cursor(blk.band_start.begin(), blk.band_start.end() - 1);
  std::vector<Pending> sorted(blk.pending.size());
  for (const Pending& p : blk.pending) sorted[cursor[band(p)]++] = p;
  blk.pending.swap(sorted);
}

// Clips the triangles of blk against every texel their UV box touches.
void clip_block(const Scene& scene, int width, int height, double mean_ratio, Block& blk) {
  const Mesh& m = scene.meshes[blk.mesh];
  for (std::size_t t = blk.first; t < blk.last; ++t) {
    const TexelTriangle tri = texel_triangle(m, t, width, height);
    const Vec2 a = tri.a, b = tri.b, c = tri.c;
    if (!(tri.uv > kDegenerateRatio * mean_ratio * tri.world) || tri.uv <= 0) {
      ++blk.degenerate;
      continue;
    }
    const double stretch = tri.world / tri.uv;  // world units^2 per texel^2 on this triangle
    const float lo_x = std::min({a.x, b.x, c.x}), hi_x = std::max({a.x, b.x, c.x});
    const float lo_y = std::min({a.y, b.y, c.y}), hi_y = std::max({a.y, b.y, c.y});
    if (lo_x < 0 || lo_y < 0 || hi_x > width || hi_y > height) ++blk.outside;
    const int x0 = std::max(0, static_cast<int>(std::floor(lo_x))), x1 = std::min(width - 1, static_cast<int>(std::floor(hi_x)));
    const int y0 = std::max(0, static_cast<int>(std::floor(lo_y))), y1 = std::min(height - 1, static_cast<int>(std::floor(hi_y)));
    // Column by column: the triangle clipped to the column once, then to each row its polygon
    // reaches. A row wholly above or below the column's polygon would clip it to nothing; the row
    // whose bottom line touches the polygon's top is kept, as a clip there can leave a sliver.
    const std::size_t first = blk.pending.size();
    for (int x = x0; x <= x1; ++x) {
      const ClipBuffers col = clip_to_column(a, b, c, x);
      if (col.n == 0) continue;
      float lo = col.corners()[0].y, hi = lo;
      for (int i = 1; i < col.n; ++i) lo = std::min(lo, col.corners()[i].y), hi = std::max(hi, col.corners()[i].y);
      // (Clamped before the conversion: the corners are those of any triangle, however far outside.)
      const auto row = [&](float v) { return static_cast<int>(std::clamp(std::floor(v), -2.0f, static_cast<float>(height))); };
      const int ya = std::max(y0, row(lo) - 1), yb = std::min(y1, row(hi));
      for (int y = ya; y <= yb; ++y) {
        const float area = clip_to_row(col, y).area();
        if (!(area > 0)) continue;
        blk.pending.push_back({static_cast<std::uint32_t>(static_cast<std::size_t>(y) * width + x),
                               {blk.mesh, static_cast<std::uint32_t>(t), area, static_cast<float>(area * stretch)}});
      }
    }
    // The triangle's fragments in texel order (row by row), as the texel-by-texel loop made them.
    std::sort(blk.pending.begin() + static_cast<std::ptrdiff_t>(first), blk.pending.end(), [](const Pending& p, const Pending& q) { return p.texel < q.texel; });
  }
  by_band(width, height, blk);
}

// The blocks' fragments sorted by texel (a counting sort, stable, so the order is deterministic),
// with each texel's areas, mask and the counts behind the warnings. Band by band in parallel (the
// blocks hold their fragments by band): a band's texels take their fragments from the blocks in
// block order, so every texel gets its fragments, and sums its areas, in the order one pass over
// the blocks would.
void gather_by_texel(std::vector<Block>& blocks, TexelCoverage& cov) {
  const std::size_t texels = cov.texel_count();
  const auto width = static_cast<std::size_t>(cov.width);
  const int bands = band_count(cov.height);
  const auto band_texels = [&](int b) {
    return std::pair{static_cast<std::size_t>(b) * kBandRows * width, std::min(texels, static_cast<std::size_t>(b + 1) * kBandRows * width)};
  };
  const auto band_fragments = [&](const Block& blk, int b) {
    return std::span(blk.pending).subspan(blk.band_start[static_cast<std::size_t>(b)], blk.band_start[static_cast<std::size_t>(b) + 1] - blk.band_start[static_cast<std::size_t>(b)]);
  };
  cov.offsets.assign(texels + 1, 0);
  for (const Block& blk : blocks) {
    cov.degenerate_uv_triangles += blk.degenerate;
    cov.outside_triangles += blk.outside;
  }
  // Each band's counts, then its running sums from 0; offsets[lo] is the previous band's.
  std::vector<std::size_t> band_base(static_cast<std::size_t>(bands) + 1, 0);
  tbb::parallel_for(0, bands, [&](int b) {
    for (const Block& blk : blocks)
      for (const Pending& p : band_fragments(blk, b)) ++cov.offsets[p.texel + 1];
    const auto [lo, hi] = band_texels(b);
    std::uint32_t run = 0;
    for (std::size_t i = lo; i < hi; ++i) cov.offsets[i + 1] = run += cov.offsets[i + 1];
    band_base[static_cast<std::size_t>(b) + 1] = run;
  });
  for (int b = 0; b < bands; ++b) band_base[static_cast<std::size_t>(b) + 1] += band_base[static_cast<std::size_t>(b)];
  cov.fragments.resize(band_base.back());
  cov.world_area = Image<float>(cov.width, cov.height, 0.0f);
  cov.uv_area = Image<float>(cov.width, cov.height, 0.0f);
  cov.mask = Image<std::uint8_t>(cov.width, cov.height, std::uint8_t{0});
  std::vector<std::size_t> covered(static_cast<std::size_t>(bands)), overlapping(static_cast<std::size_t>(bands));
  tbb::parallel_for(0, bands, [&](int b) {
    const auto [lo, hi] = band_texels(b);
    const auto base = static_cast<std::uint32_t>(band_base[static_cast<std::size_t>(b)]);
    // offsets[lo] is the previous band's last entry, which that band may still be raising by its
    // own base; its final value is this band's base, so the cursors start from that.
    std::vector<std::uint32_t> cursor(hi - lo);
    cursor[0] = base;
    for (std::size_t i = lo; i < hi; ++i) {
      cov.offsets[i + 1] += base;
      if (i + 1 < hi) cursor[i + 1 - lo] = cov.offsets[i + 1];
    }
    for (const Block& blk : blocks)
      for (const Pending& p : band_fragments(blk, b)) {
        cov.fragments[cursor[p.texel - lo]++] = p.frag;
        cov.world_area[p.texel] += p.frag.world_area;
        cov.uv_area[p.texel] += p.frag.uv_area;
      }
    for (std::size_t i = lo; i < hi; ++i) {
      if (cov.world_area[i] > 0) {
        cov.mask[i] = 1;
        ++covered[static_cast<std::size_t>(b)];
      }
      // 1% slack: clipped areas of triangles sharing an edge sum to the texel area up to rounding.
      if (cov.uv_area[i] > 1.01f) ++overlapping[static_cast<std::size_t>(b)];
    }
  });
  for (int b = 0; b < bands; ++b) cov.covered_texels += covered[static_cast<std::size_t>(b)], cov.overlapping_texels += overlapping[static_cast<std::size_t>(b)];
  for (Block& blk : blocks) std::vector<Pending>().swap(blk.pending);
}

}  // namespace

TexelCoverage compute_texel_coverage(const Scene& scene, int width, int height) {
  require_no_instances(scene);
  for (const int side : {width, height})
    if (side < 1 || side > kMaxSize) throw InputError("bake: map width and height must be in [1, " + std::to_string(kMaxSize) + "], got " + std::to_string(width) + "x" + std::to_string(height));
  TexelCoverage cov;
  cov.width = width;
  cov.height = height;
  const double mean_ratio = mean_texel_ratio(scene, width, height);  // texels^2 per world unit^2

  // Blocks of triangles over all meshes, clipped in parallel, concatenated in block order.
  std::vector<Block> blocks;
  for (std::size_t mi = 0; mi < scene.meshes.size(); ++mi) {
    const Mesh& m = scene.meshes[mi];
    if (m.uvs.empty()) continue;
    for (std::size_t t = 0; t < m.triangle_count(); t += kBlock)
      blocks.push_back({static_cast<std::uint32_t>(mi), t, std::min(m.triangle_count(), t + kBlock), {}});
  }
  tbb::parallel_for(std::size_t{0}, blocks.size(), [&](std::size_t bi) { clip_block(scene, width, height, mean_ratio, blocks[bi]); });
  gather_by_texel(blocks, cov);
  if (cov.covered_texels == 0) throw InputError(scene.name + ": no triangle's UVs fall inside [0,1]^2; nothing to bake");
  return cov;
}

}  // namespace ao
