// SPDX-License-Identifier: Apache-2.0
// Patch sampling for the inside-out bakers: see texel_rays_internal.h.
#include "ao/bake/texel_rays_internal.h"

#include <algorithm>
#include <cmath>

#include "ao/reference/ray_offset.h"
#include "ao/simd/sampling_internal.h"

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

void build_patch(const Scene& s, const TexelCoverage& cov, const TriangleNormals& fn, std::span<const TexelPiece> fragments,
                 std::vector<PatchPiece>& out) {
  out.clear();
  double acc = 0;
  for (const TexelPiece& piece : fragments) {
    const TexelFragment& fr = piece.fragment;
    const Mesh& m = s.meshes[fr.mesh];
    const std::uint32_t* i = &m.indices[3 * fr.triangle];
    const Vec2 a = texel_uv(m, i[0], cov.width, cov.height), b = texel_uv(m, i[1], cov.width, cov.height), c = texel_uv(m, i[2], cov.width, cov.height);
    const ClipPolygon& poly = piece.polygon;
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

namespace {

Vec2 sub(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
float dot2(Vec2 a, Vec2 b) { return a.x * b.x + a.y * b.y; }
Vec2 weighted(Vec2 a, Vec2 b, Vec2 c, Vec3 l) { return {a.x * l.x + b.x * l.y + c.x * l.z, a.y * l.x + b.y * l.y + c.y * l.z}; }

// The point of triangle (a, b, c) nearest to q, as barycentrics: q's own when inside, else the
// nearest point of the nearest edge.
Vec3 nearest_barycentrics(Vec2 a, Vec2 b, Vec2 c, Vec2 q) {
  const float det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
  if (det != 0) {
    const float l1 = ((q.x - a.x) * (c.y - a.y) - (c.x - a.x) * (q.y - a.y)) / det;
    const float l2 = ((b.x - a.x) * (q.y - a.y) - (q.x - a.x) * (b.y - a.y)) / det;
    if (l1 >= 0 && l2 >= 0 && l1 + l2 <= 1) return {1 - l1 - l2, l1, l2};
  }
  Vec3 best{1, 0, 0};
  float best_d2 = kInfinity;
  const Vec2 v[3] = {a, b, c};
  for (int e = 0; e < 3; ++e) {
    const Vec2 p = v[e], d = sub(v[(e + 1) % 3], p);
    const float len2 = dot2(d, d);
    const float t = len2 > 0 ? std::clamp(dot2(sub(q, p), d) / len2, 0.0f, 1.0f) : 0.0f;
    const Vec2 off = sub(q, Vec2{p.x + d.x * t, p.y + d.y * t});
    if (const float d2 = dot2(off, off); d2 < best_d2) {
      best_d2 = d2;
      float l[3] = {0, 0, 0};
      l[e] = 1 - t, l[(e + 1) % 3] = t;
      best = {l[0], l[1], l[2]};
    }
  }
  return best;
}

}  // namespace

void centre_patch(const TexelSource& texels, std::size_t texel, std::span<const TexelPiece> fragments, const std::vector<PatchPiece>& patch,
                  std::vector<PatchPiece>& out) {
  const TexelCoverage& cov = texels.cov;
  const Vec2 q{static_cast<float>(texel % static_cast<std::size_t>(cov.width)) + 0.5f,
               static_cast<float>(texel / static_cast<std::size_t>(cov.width)) + 0.5f};
  float best_d2 = kInfinity;
  PatchPiece pc;  // (its Vec3s start at 0; the rest set here, should no fragment's distance compare)
  pc.mesh = 0, pc.triangle = 0, pc.offset = 0.0f;
  for (std::size_t f = 0; f < fragments.size() && best_d2 > 0; ++f) {
    const TexelFragment& fr = fragments[f].fragment;
    const Mesh& m = texels.scene.meshes[fr.mesh];
    const std::uint32_t* i = &m.indices[3 * fr.triangle];
    const Vec2 a = texel_uv(m, i[0], cov.width, cov.height), b = texel_uv(m, i[1], cov.width, cov.height), c = texel_uv(m, i[2], cov.width, cov.height);
    const Vec3 l = nearest_barycentrics(a, b, c, q);
    const Vec2 off = sub(q, weighted(a, b, c, l));
    const float d2 = dot2(off, off);
    if (!(d2 < best_d2)) continue;
    best_d2 = d2;
    pc.mesh = fr.mesh;
    pc.triangle = fr.triangle;
    const Vec3 p = m.positions[i[0]] * l.x + m.positions[i[1]] * l.y + m.positions[i[2]] * l.z;
    const Vec3 n = m.normals[i[0]] * l.x + m.normals[i[1]] * l.y + m.normals[i[2]] * l.z;
    pc.p = {p, p, p};
    pc.n = {n, n, n};
    pc.bary = {l, l, l};
    pc.ng = texels.fn.per_mesh[fr.mesh][fr.triangle];
    pc.offset = ray_offset_distance(triangle_magnitude(m, fr.triangle));
  }
  pc.cdf = patch.back().cdf;
  out.assign(1, pc);
}

void patch_guide(const std::vector<PatchPiece>& patch, bool geometric, Vec3& position, Vec3& normal) {
  Vec3 c{0, 0, 0}, n{0, 0, 0};
  float lo = 0;
  for (const PatchPiece& pc : patch) {
    const float area = pc.cdf - lo;
    lo = pc.cdf;
    c += (pc.p[0] + pc.p[1] + pc.p[2]) * (area / 3.0f);
    n += geometric ? pc.ng * area : (pc.n[0] + pc.n[1] + pc.n[2]) * area;
  }
  position = lo > 0 ? c / lo : patch[0].p[0];
  const float len = length(n);
  normal = len > 0 ? n / len : patch[0].ng;
}


void TexelPoints::generate(const TexelSampleSet& set, int samples) {
  const auto n = static_cast<std::size_t>(samples);
  // Grid of 2^c cells, 2^c the largest power of two <= samples / 16, as square as it goes.
  int c = 0;
  while ((32 << c) <= samples) ++c;
  // One cell (fewer than 32 samples): direction order is index order, so the points go straight
  // to u, without the sort.
  std::vector<float>(&dest)[4] = c == 0 ? u : scratch;
  for (int d = 0; d < 4; ++d) dest[d].resize(n);
  alignas(64) float batch[4][16];
  for (int first = 0; first < samples; first += 16) {
    const int count = std::min(16, samples - first);
    sobol_owen_4d_batch(set.first + static_cast<std::uint32_t>(first), count, set.key, batch);
    for (int d = 0; d < 4; ++d) std::copy_n(batch[d], count, dest[d].begin() + first);
  }
  if (c == 0) return;
  for (int d = 0; d < 4; ++d) u[d].resize(n);
  const int cols = 1 << ((c + 1) / 2), rows = 1 << (c / 2);
  cell_of.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const int a = std::min(static_cast<int>(scratch[0][i] * static_cast<float>(cols)), cols - 1);
    const int b = std::min(static_cast<int>(scratch[1][i] * static_cast<float>(rows)), rows - 1);
    cell_of[i] = static_cast<std::uint32_t>(a * rows + b);
  }
  // Counting sort by cell, stable.
  cell_count.assign(static_cast<std::size_t>(cols * rows) + 1, 0);
  for (std::size_t i = 0; i < n; ++i) ++cell_count[cell_of[i] + 1];
  for (std::size_t k = 1; k < cell_count.size(); ++k) cell_count[k] += cell_count[k - 1];
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t to = cell_count[cell_of[i]]++;
    for (int d = 0; d < 4; ++d) u[d][to] = scratch[d][i];
  }
}

void StratifiedVariance::reset(int samples) {
  int m = 0;
  while ((2 << m) <= samples) ++m;  // 2^m <= samples < 2^(m+1)
  // 2^(m-1) cells, as square as it goes.
  const int c = std::max(m - 1, 0);
  cols_ = 1 << ((c + 1) / 2), rows_ = 1 << (c / 2);
  cells_.assign(static_cast<std::size_t>(cols_ * rows_), Sums{});
}

double StratifiedVariance::mean_variance() const {
  double within = 0, pooled_ss = 0;
  int n = 0, singles = 0, pooled_dof = 0;
  for (const Sums& c : cells_) {
    n += c.n;
    if (c.n == 1) ++singles;
    if (c.n < 2) continue;
    const double ss = std::max(0.0, c.sum_sq - c.sum * c.sum / c.n);  // squares about the cell's mean: (n_c - 1) s_c^2
    within += ss * c.n / (c.n - 1);  // n_c s_c^2
    pooled_ss += ss;
    pooled_dof += c.n - 1;
  }
  if (n < 2) return 0.0;
  if (pooled_dof == 0) {
    // No cell holds two samples (fewer than four samples): the plain sample variance.
    double sum = 0, sum_sq = 0;
    for (const Sums& c : cells_) sum += c.sum, sum_sq += c.sum_sq;
    return std::max(0.0, (sum_sq - sum * sum / n) / (n - 1)) / n;
  }
  within += singles * (pooled_ss / pooled_dof);  // a lone sample's cell: the pooled within-cell variance
  return within / (static_cast<double>(n) * n);
}

void TexelPoints::lanes(int first, int count, float (&out)[4][16]) const {
  for (int d = 0; d < 4; ++d) {
    std::copy_n(u[d].begin() + first, count, out[d]);
    std::fill(out[d] + count, out[d] + 16, 0.5f);  // unused lanes: any point
  }
}

void PatchTable::piece_fields(const std::vector<PatchPiece>& patch, std::size_t j, float (&v)[kFields]) const {
  const PatchPiece& pc = patch[j];
  for (int c = 0; c < 3; ++c) {
    v[kP + 3 * c] = pc.p[c].x, v[kP + 3 * c + 1] = pc.p[c].y, v[kP + 3 * c + 2] = pc.p[c].z;
    v[kN + 3 * c] = pc.n[c].x, v[kN + 3 * c + 1] = pc.n[c].y, v[kN + 3 * c + 2] = pc.n[c].z;
  }
  v[kNg] = pc.ng.x, v[kNg + 1] = pc.ng.y, v[kNg + 2] = pc.ng.z;
  v[kOff] = fixed_offset > 0 ? fixed_offset : pc.offset;
  v[kLo] = j == 0 ? 0.0f : patch[j - 1].cdf;
  const float span = pc.cdf - v[kLo];
  v[kInvSpan] = span > 0 ? 1.0f / span : 0.0f;  // an empty piece: its first corner (r = 0)
}

void PatchTable::build(const std::vector<PatchPiece>& patch, float offset) {
  fixed_offset = offset;
  if (patch.size() > kMaxPieces) return;
  for (std::size_t j = 0; j < patch.size(); ++j) {
    float v[kFields];
    piece_fields(patch, j, v);
    for (int q = 0; q < kFields; ++q) f[q][j] = v[q];
  }
}

}  // namespace ao::detail
