// SPDX-License-Identifier: Apache-2.0
// Exact UV coverage of the texel grid. Each triangle is clipped (Sutherland-Hodgman) against every
// texel square its UV bounding box touches, column by column: to the column's two lines once, then
// that polygon to the two lines of each row it reaches (the clips clip_to_texel makes, in its
// order); the clipped area, scaled by the triangle's ratio of world area to UV area (constant over
// a triangle, since the parameterisation is linear there: the paper's sec. 3, after eq. 3), is
// that texel's share of surface. Summing these shares gives
// the exact denominator of eq. 2/3 without the paper's assumption that stretch is constant over a
// texel (eq. 4), which fails at chart borders and where triangles of different stretch meet.
// The triangles are first sorted into bins of 8 x 8 texels by their boxes; each bin then sums its
// texels' shares on its own (in parallel), and texel_fragments clips a texel's triangles again from
// its bin when a baker asks for them.
#include "ao/bake/texel_coverage.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>

#include "ao/core/error.h"
#include "ao/core/memory.h"

namespace ao {

namespace {

constexpr int kMaxSize = 16384;
// A UV triangle smaller than this many texels^2 per world unit^2 of surface, relative to the
// map, counts as degenerate: its texels would get a weight 1e6 times the average.
constexpr double kDegenerateRatio = 1e-6;

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
    const Vec2 a = p[i], b = p[i + 1 == n ? 0 : i + 1];  // (not % n: a division per corner)
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

// Triangle t of mesh m as the bins list it: its box of texels on the map and its stretch. false
// for a triangle that gets no texel: degenerate in UV (counted in `degenerate`) or with its box
// off the map; `outside` counts those reaching outside the map.
bool bin_entry(const Mesh& m, std::uint32_t mesh, std::uint32_t t, int width, int height, double mean_ratio, BinnedTriangle& e,
               std::size_t& degenerate, std::size_t& outside) {
  const TexelTriangle tri = texel_triangle(m, t, width, height);
  const Vec2 a = tri.a, b = tri.b, c = tri.c;
  if (!(tri.uv > kDegenerateRatio * mean_ratio * tri.world) || tri.uv <= 0) {
    ++degenerate;
    return false;
  }
  const float lo_x = std::min({a.x, b.x, c.x}), hi_x = std::max({a.x, b.x, c.x});
  const float lo_y = std::min({a.y, b.y, c.y}), hi_y = std::max({a.y, b.y, c.y});
  if (lo_x < 0 || lo_y < 0 || hi_x > width || hi_y > height) ++outside;
  // The texels whose squares the box touches, clamped to the map (in float first: the corners
  // are those of any triangle, however far outside).
  const float x0 = std::max(0.0f, std::floor(lo_x)), x1 = std::min(static_cast<float>(width - 1), std::floor(hi_x));
  const float y0 = std::max(0.0f, std::floor(lo_y)), y1 = std::min(static_cast<float>(height - 1), std::floor(hi_y));
  if (!(x0 <= x1 && y0 <= y1)) return false;
  e = {mesh, t, static_cast<std::uint16_t>(x0), static_cast<std::uint16_t>(y0), static_cast<std::uint16_t>(x1), static_cast<std::uint16_t>(y1),
       tri.world / tri.uv};
  return true;
}

std::size_t bin_index(const TexelCoverage& cov, int bx, int by) {
  return static_cast<std::size_t>(by) * static_cast<std::size_t>(cov.bin_columns) + static_cast<std::size_t>(bx);
}

// Every triangle with UVs into the bins its box touches, in mesh then triangle order (a counting
// sort: one pass counts, the second places). The triangles' boxes are found in parallel.
void bin_triangles(const Scene& scene, double mean_ratio, TexelCoverage& cov) {
  constexpr int kBin = TexelCoverage::kBin;
  constexpr std::size_t kBlock = 4096;  // triangles per parallel block
  cov.bin_columns = (cov.width + kBin - 1) / kBin;
  const int bin_rows = (cov.height + kBin - 1) / kBin;
  const auto bins = static_cast<std::size_t>(cov.bin_columns) * static_cast<std::size_t>(bin_rows);
  struct Block {
    std::uint32_t mesh;
    std::size_t first, last;
    std::vector<BinnedTriangle> entries;
    std::size_t degenerate = 0, outside = 0;
  };
  std::vector<Block> blocks;
  for (std::size_t mi = 0; mi < scene.meshes.size(); ++mi)
    if (!scene.meshes[mi].uvs.empty())
      for (std::size_t t = 0; t < scene.meshes[mi].triangle_count(); t += kBlock)
        blocks.push_back({static_cast<std::uint32_t>(mi), t, std::min(scene.meshes[mi].triangle_count(), t + kBlock), {}});
  tbb::parallel_for(std::size_t{0}, blocks.size(), [&](std::size_t bi) {
    Block& blk = blocks[bi];
    for (std::size_t t = blk.first; t < blk.last; ++t) {
      BinnedTriangle e;
      if (bin_entry(scene.meshes[blk.mesh], blk.mesh, static_cast<std::uint32_t>(t), cov.width, cov.height, mean_ratio, e, blk.degenerate,
                    blk.outside))
        blk.entries.push_back(e);
    }
  });
  const auto for_each_bin = [&](const BinnedTriangle& e, auto&& fn) {
    for (int by = e.y0 / kBin; by <= e.y1 / kBin; ++by)
      for (int bx = e.x0 / kBin; bx <= e.x1 / kBin; ++bx) fn(bin_index(cov, bx, by));
  };
  std::uint64_t total = 0;
  for (const Block& blk : blocks) {
    cov.degenerate_uv_triangles += blk.degenerate, cov.outside_triangles += blk.outside;
    for (const BinnedTriangle& e : blk.entries)
      total += static_cast<std::uint64_t>(e.x1 / kBin - e.x0 / kBin + 1) * static_cast<std::uint64_t>(e.y1 / kBin - e.y0 / kBin + 1);
  }
  if (total > std::numeric_limits<std::uint32_t>::max())
    throw InputError(scene.name + ": its UV triangles reach " + std::to_string(total) + " bins of " + std::to_string(kBin) + "^2 texels, " +
                     "more than a map can list (2^32); bake a smaller map");
  check_memory(total * sizeof(BinnedTriangle), "the UV layout's bins");
  cov.bin_offsets.assign(bins + 1, 0);
  for (const Block& blk : blocks)
    for (const BinnedTriangle& e : blk.entries) for_each_bin(e, [&](std::size_t b) { ++cov.bin_offsets[b + 1]; });
  for (std::size_t b = 0; b < bins; ++b) cov.bin_offsets[b + 1] += cov.bin_offsets[b];
  std::vector<std::uint32_t> cursor(cov.bin_offsets.begin(), cov.bin_offsets.end() - 1);
  cov.binned.resize(cov.bin_offsets.back());
  for (const Block& blk : blocks)
    for (const BinnedTriangle& e : blk.entries) for_each_bin(e, [&](std::size_t b) { cov.binned[cursor[b]++] = e; });
}

// The triangle of a binned entry in texel units.
struct BinnedCorners {
  Vec2 a, b, c;
};
BinnedCorners corners(const Scene& scene, const BinnedTriangle& e, int width, int height) {
  const Mesh& m = scene.meshes[e.mesh];
  const std::uint32_t* i = &m.indices[3 * static_cast<std::size_t>(e.triangle)];
  return {texel_uv(m, i[0], width, height), texel_uv(m, i[1], width, height), texel_uv(m, i[2], width, height)};
}

// Rows y_lo .. y_hi (clamped to the entry's box) that a column's polygon can reach: a row wholly
// above or below it would clip it to nothing; the row whose bottom line touches the polygon's top
// is kept, as a clip there can leave a sliver.
std::pair<int, int> column_rows(const ClipBuffers& col, const BinnedTriangle& e, int height) {
  float lo = col.corners()[0].y, hi = lo;
  for (int i = 1; i < col.n; ++i) lo = std::min(lo, col.corners()[i].y), hi = std::max(hi, col.corners()[i].y);
  // (Clamped before the conversion: the corners are those of any triangle, however far outside.)
  const auto row = [&](float v) { return static_cast<int>(std::clamp(std::floor(v), -2.0f, static_cast<float>(height))); };
  return {std::max(static_cast<int>(e.y0), row(lo) - 1), std::min(static_cast<int>(e.y1), row(hi))};
}

// The fragment of entry e whose clipped area is `area` (texels^2).
TexelFragment fragment(const BinnedTriangle& e, float area) { return {e.mesh, e.triangle, area, static_cast<float>(area * e.stretch)}; }

// Texels x0 .. x1, y0 .. y1 of bin (bx, by), inclusive.
struct BinTexels {
  int x0, y0, x1, y1;
};
BinTexels bin_texels(const TexelCoverage& cov, int bx, int by) {
  constexpr int kBin = TexelCoverage::kBin;
  return {bx * kBin, by * kBin, std::min(cov.width, (bx + 1) * kBin) - 1, std::min(cov.height, (by + 1) * kBin) - 1};
}

// fn(entry, x, y, polygon, area) for every fragment of bin (bx, by) in its texels `bt` (the whole
// bin, or part of it), entry by entry in the bin's order (mesh, then triangle): the triangle
// clipped to each column of `bt` it reaches once, then that polygon to each row of `bt` it can
// reach (the clips clip_to_texel makes, in its order).
template <class Fn>
void clip_bin(const Scene& scene, const TexelCoverage& cov, int bx, int by, BinTexels bt, Fn&& fn) {
  const std::size_t b = bin_index(cov, bx, by);
  for (std::uint32_t k = cov.bin_offsets[b]; k < cov.bin_offsets[b + 1]; ++k) {
    const BinnedTriangle& e = cov.binned[k];
    const BinnedCorners t = corners(scene, e, cov.width, cov.height);
    for (int x = std::max(bt.x0, static_cast<int>(e.x0)); x <= std::min(bt.x1, static_cast<int>(e.x1)); ++x) {
      const ClipBuffers col = clip_to_column(t.a, t.b, t.c, x);
      if (col.n == 0) continue;
      const auto [ya, yb] = column_rows(col, e, cov.height);
      for (int y = std::max(ya, bt.y0); y <= std::min(yb, bt.y1); ++y) {
        const ClipPolygon poly = clip_to_row(col, y);
        const float area = poly.area();
        if (area > 0) fn(e, x, y, poly, area);
      }
    }
  }
}

// The sums of bin (bx, by): each texel's areas over its fragments in the bin's order, its mask,
// and the bin's counts.
struct BinCounts {
  std::size_t fragments = 0, covered = 0, overlapping = 0;
};
BinCounts sum_bin(const Scene& scene, TexelCoverage& cov, int bx, int by) {
  BinCounts n;
  const BinTexels bt = bin_texels(cov, bx, by);
  clip_bin(scene, cov, bx, by, bt, [&](const BinnedTriangle& e, int x, int y, const ClipPolygon&, float area) {
    const std::size_t texel = static_cast<std::size_t>(y) * static_cast<std::size_t>(cov.width) + static_cast<std::size_t>(x);
    const TexelFragment f = fragment(e, area);
    cov.uv_area[texel] += f.uv_area;
    cov.world_area[texel] += f.world_area;
    ++n.fragments;
  });
  for (int y = bt.y0; y <= bt.y1; ++y)
    for (int x = bt.x0; x <= bt.x1; ++x) {
      const std::size_t texel = static_cast<std::size_t>(y) * static_cast<std::size_t>(cov.width) + static_cast<std::size_t>(x);
      if (cov.world_area[texel] > 0) {
        cov.mask[texel] = 1;
        ++n.covered;
      }
      // 1% slack: clipped areas of triangles sharing an edge sum to the texel area up to rounding.
      if (cov.uv_area[texel] > 1.01f) ++n.overlapping;
    }
  return n;
}

}  // namespace

void texel_fragments(const Scene& scene, const TexelCoverage& cov, std::size_t texel, std::vector<TexelPiece>& out) {
  out.clear();
  const int x = static_cast<int>(texel % static_cast<std::size_t>(cov.width)), y = static_cast<int>(texel / static_cast<std::size_t>(cov.width));
  clip_bin(scene, cov, x / TexelCoverage::kBin, y / TexelCoverage::kBin, {x, y, x, y},
           [&](const BinnedTriangle& e, int, int, const ClipPolygon& poly, float area) { out.push_back({fragment(e, area), poly}); });
}

void bin_fragments(const Scene& scene, const TexelCoverage& cov, int bx, int by, BinFragments& out) {
  constexpr int kBin = TexelCoverage::kBin;
  out.scratch.clear();
  out.texel_of.clear();
  clip_bin(scene, cov, bx, by, bin_texels(cov, bx, by), [&](const BinnedTriangle& e, int x, int y, const ClipPolygon& poly, float area) {
    out.scratch.push_back({fragment(e, area), poly});
    out.texel_of.push_back(static_cast<std::uint8_t>((y - by * kBin) * kBin + (x - bx * kBin)));
  });
  // By texel, stably (a counting sort): each texel's fragments stay in the bin's order.
  out.offsets.fill(0);
  for (const std::uint8_t k : out.texel_of) ++out.offsets[k + 1u];
  for (std::size_t k = 1; k < out.offsets.size(); ++k) out.offsets[k] += out.offsets[k - 1];
  std::array<std::uint32_t, kBin * kBin> cursor;
  std::copy_n(out.offsets.begin(), cursor.size(), cursor.begin());
  out.pieces.resize(out.scratch.size());
  for (std::size_t f = 0; f < out.scratch.size(); ++f) out.pieces[cursor[out.texel_of[f]]++] = out.scratch[f];
}

TexelCoverage compute_texel_coverage(const Scene& scene, int width, int height) {
  require_no_instances(scene);
  for (const int side : {width, height})
    if (side < 1 || side > kMaxSize) throw InputError("bake: map width and height must be in [1, " + std::to_string(kMaxSize) + "], got " + std::to_string(width) + "x" + std::to_string(height));
  TexelCoverage cov;
  cov.width = width;
  cov.height = height;
  const double mean_ratio = mean_texel_ratio(scene, width, height);  // texels^2 per world unit^2

  bin_triangles(scene, mean_ratio, cov);
  cov.world_area = Image<float>(width, height, 0.0f);
  cov.uv_area = Image<float>(width, height, 0.0f);
  cov.mask = Image<std::uint8_t>(width, height, std::uint8_t{0});
  // Bin by bin in parallel: a bin's texels are its own, and each texel sums its fragments in the
  // bin's order, so the sums are the same at any thread count.
  const int bin_rows = (height + TexelCoverage::kBin - 1) / TexelCoverage::kBin;
  std::vector<BinCounts> row_counts(static_cast<std::size_t>(bin_rows));
  tbb::parallel_for(0, bin_rows, [&](int by) {
    BinCounts& r = row_counts[static_cast<std::size_t>(by)];
    for (int bx = 0; bx < cov.bin_columns; ++bx) {
      const BinCounts n = sum_bin(scene, cov, bx, by);
      r.fragments += n.fragments, r.covered += n.covered, r.overlapping += n.overlapping;
    }
  });
  for (const BinCounts& r : row_counts) cov.fragments += r.fragments, cov.covered_texels += r.covered, cov.overlapping_texels += r.overlapping;
  if (cov.covered_texels == 0) throw InputError(scene.name + ": no triangle's UVs fall inside [0,1]^2; nothing to bake");
  return cov;
}

}  // namespace ao
