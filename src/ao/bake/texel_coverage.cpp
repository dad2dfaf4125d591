// Exact UV coverage of the texel grid. Each triangle is clipped (Sutherland-Hodgman) against every
// texel square its UV bounding box touches; the clipped area, scaled by the triangle's ratio of
// world area to UV area (constant over a triangle, since the parameterisation is linear there:
// the paper's sec. 3, after eq. 3), is that texel's share of surface. Summing these shares gives
// the exact denominator of eq. 2/3 without the paper's assumption that stretch is constant over a
// texel (eq. 4), which fails at chart borders and where triangles of different stretch meet.
#include "ao/bake/texel_coverage.h"

#include <cmath>

#include <tbb/parallel_for.h>

#include "ao/core/error.h"

namespace ao {

namespace {

constexpr int kMaxSize = 16384;
constexpr std::size_t kBlock = 4096;  // triangles per parallel block (blocks are merged in order)
// A UV triangle smaller than this many texels^2 per world unit^2 of surface, relative to the
// map, counts as degenerate: its texels would get a weight 1e6 times the average.
constexpr double kDegenerateRatio = 1e-6;

struct Pending {
  std::uint32_t texel;
  TexelFragment frag;
};

ClipPolygon clip_half_plane(const ClipPolygon& in, int axis, float bound, bool keep_greater) {
  ClipPolygon out;
  auto inside = [&](Vec2 p) {
    const float c = axis == 0 ? p.x : p.y;
    return keep_greater ? c >= bound : c <= bound;
  };
  for (int i = 0; i < in.n; ++i) {
    const Vec2 a = in.p[i], b = in.p[i + 1 == in.n ? 0 : i + 1];
    const bool ia = inside(a), ib = inside(b);
    if (ia) out.p[out.n++] = a;
    if (ia != ib) {
      const float ca = axis == 0 ? a.x : a.y, cb = axis == 0 ? b.x : b.y;
      const float t = (bound - ca) / (cb - ca);
      Vec2 q{a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)};
      if (axis == 0) q.x = bound;
      else q.y = bound;
      out.p[out.n++] = q;
    }
  }
  return out;
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

ClipPolygon clip_to_texel(Vec2 a, Vec2 b, Vec2 c, int x, int y) {
  ClipPolygon poly;
  poly.p[0] = a;
  poly.p[1] = b;
  poly.p[2] = c;
  poly.n = 3;
  poly = clip_half_plane(poly, 0, static_cast<float>(x), true);
  poly = clip_half_plane(poly, 0, static_cast<float>(x + 1), false);
  poly = clip_half_plane(poly, 1, static_cast<float>(y), true);
  poly = clip_half_plane(poly, 1, static_cast<float>(y + 1), false);
  return poly;
}

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
  std::vector<Pending> pending;  // the run's fragments, in triangle then texel order
  std::size_t degenerate = 0, outside = 0;
};

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
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const float area = clip_to_texel(a, b, c, x, y).area();
        if (!(area > 0)) continue;
        blk.pending.push_back({static_cast<std::uint32_t>(static_cast<std::size_t>(y) * width + x),
                               {blk.mesh, static_cast<std::uint32_t>(t), area, static_cast<float>(area * stretch)}});
      }
  }
}

// The blocks' fragments sorted by texel (a counting sort, stable, so the order is deterministic),
// with each texel's areas, mask and the counts behind the warnings.
void gather_by_texel(std::vector<Block>& blocks, TexelCoverage& cov) {
  const std::size_t texels = cov.texel_count();
  cov.offsets.assign(texels + 1, 0);
  std::size_t total = 0;
  for (const Block& blk : blocks) {
    cov.degenerate_uv_triangles += blk.degenerate;
    cov.outside_triangles += blk.outside;
    total += blk.pending.size();
    for (const Pending& p : blk.pending) ++cov.offsets[p.texel + 1];
  }
  for (std::size_t i = 0; i < texels; ++i) cov.offsets[i + 1] += cov.offsets[i];
  cov.fragments.resize(total);
  std::vector<std::uint32_t> cursor(cov.offsets.begin(), cov.offsets.end() - 1);
  cov.world_area = Image<float>(cov.width, cov.height, 0.0f);
  cov.uv_area = Image<float>(cov.width, cov.height, 0.0f);
  cov.mask = Image<std::uint8_t>(cov.width, cov.height, std::uint8_t{0});
  for (Block& blk : blocks) {
    for (const Pending& p : blk.pending) {
      cov.fragments[cursor[p.texel]++] = p.frag;
      cov.world_area[p.texel] += p.frag.world_area;
      cov.uv_area[p.texel] += p.frag.uv_area;
    }
    std::vector<Pending>().swap(blk.pending);
  }
  for (std::size_t i = 0; i < texels; ++i) {
    if (cov.world_area[i] > 0) {
      cov.mask[i] = 1;
      ++cov.covered_texels;
    }
    // 1% slack: clipped areas of triangles sharing an edge sum to the texel area up to rounding.
    if (cov.uv_area[i] > 1.01f) ++cov.overlapping_texels;
  }
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
