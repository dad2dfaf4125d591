// Patch sampling for the inside-out bakers: see texel_rays_internal.h.
#include "ao/bake/texel_rays_internal.h"

#include <algorithm>
#include <cmath>

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

namespace {

// sin t and cos t for t in [-pi/4, pi/4], from their Taylor series to degree 9 and 10: the
// remainders, |t|^11/11! and |t|^12/12!, are below 2e-9 there, under float rounding.
inline void sincos_quarter(float t, float& s, float& c) {
  const float t2 = t * t;
  s = t * (1.0f + t2 * (-1.0f / 6 + t2 * (1.0f / 120 + t2 * (-1.0f / 5040 + t2 * (1.0f / 362880)))));
  c = 1.0f + t2 * (-1.0f / 2 + t2 * (1.0f / 24 + t2 * (-1.0f / 720 + t2 * (1.0f / 40320 + t2 * (-1.0f / 3628800)))));
}

// cosine_hemisphere: the concentric map with phi = (pi/4)(b/a) when |a| > |b|, else
// pi/2 - (pi/4)(a/b), whose cosine and sine are the sine and cosine of (pi/4)(a/b).
inline void concentric_hemisphere(float u0, float u1, float& lx, float& ly, float& lz) {
  const float ca = 2.0f * u0 - 1.0f, cb = 2.0f * u1 - 1.0f;
  const bool use_a = std::abs(ca) > std::abs(cb);
  const float rad = use_a ? ca : cb, q = use_a ? cb : ca;
  float s, c;
  sincos_quarter((kPi / 4) * (q / (rad != 0.0f ? rad : 1.0f)), s, c);  // a = b = 0: rad = 0, so (0, 0, 1)
  lx = rad * (use_a ? c : s), ly = rad * (use_a ? s : c);
  lz = std::sqrt(std::max(0.0f, 1.0f - lx * lx - ly * ly));
}

}  // namespace

void TexelPoints::generate(std::uint32_t key, int samples) {
  const auto n = static_cast<std::size_t>(samples);
  for (int d = 0; d < 4; ++d) {
    u[d].resize(n);
    scratch[d].resize(n);
  }
  alignas(64) float batch[4][16];
  for (int first = 0; first < samples; first += 16) {
    const int count = std::min(16, samples - first);
    sobol_owen_4d_batch(static_cast<std::uint32_t>(first), count, key, batch);
    for (int d = 0; d < 4; ++d) std::copy_n(batch[d], count, scratch[d].begin() + first);
  }
  // Grid of 2^c cells, 2^c the largest power of two <= samples / 16, as square as it goes.
  int c = 0;
  while ((32 << c) <= samples) ++c;
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

void make_texel_rays(const std::vector<PatchPiece>& patch, const PatchTable& table, const float (&u)[4][16], int count, bool geometric,
                     TexelRayBatch& out) {
  constexpr int W = TexelRayBatch::kWidth;
  using T = PatchTable;
  // Per lane, the piece (sample_patch's: the first whose cumulative area exceeds u2 * total; the
  // cumulative areas are non-decreasing) and its fields, looked up from the texel's table (a
  // permute across a register for each field), so that the arithmetic below reads only lane
  // arrays and vectorises.
  alignas(64) float lane[T::kFields][W];
  alignas(64) float su[W], target[W];
  alignas(64) int piece[W];
  const float total = patch.back().cdf;
  for (int k = 0; k < W; ++k) target[k] = u[2][k] * total, piece[k] = 0;
  for (std::size_t j = 0; j + 1 < patch.size(); ++j) {
    const float cj = patch[j].cdf;
    for (int k = 0; k < W; ++k) piece[k] += cj <= target[k] ? 1 : 0;
  }
  if (patch.size() <= T::kMaxPieces) {
    for (int q = 0; q < T::kFields; ++q)
      for (int k = 0; k < W; ++k) lane[q][k] = table.f[q][piece[k]];
  } else {
    for (int k = 0; k < W; ++k) {
      float v[T::kFields];
      table.piece_fields(patch, static_cast<std::size_t>(piece[k]), v);
      for (int q = 0; q < T::kFields; ++q) lane[q][k] = v[q];
    }
  }
  constexpr int kP = T::kP, kN = T::kN, kNg = T::kNg, kOff = T::kOff, kLo = T::kLo, kInvSpan = T::kInvSpan;
  for (int k = 0; k < W; ++k) su[k] = std::min(std::max((target[k] - lane[kLo][k]) * lane[kInvSpan][k], 0.0f), 1.0f);
  for (int k = 0; k < W; ++k) {
    // The point: corner weights (1 - r, r (1 - t), r t), r = sqrt(s), as sample_patch.
    const float r = std::sqrt(su[k]);
    const float w0 = 1.0f - r, w1 = r * (1.0f - u[3][k]), w2 = r * u[3][k];
    float pos[3], nrm[3];
    for (int a = 0; a < 3; ++a) {
      pos[a] = lane[kP + a][k] * w0 + lane[kP + 3 + a][k] * w1 + lane[kP + 6 + a][k] * w2;
      nrm[a] = lane[kN + a][k] * w0 + lane[kN + 3 + a][k] * w1 + lane[kN + 6 + a][k] * w2;
    }
    // The unit normal (PatchSample::normal: the face normal where the vertex normals cancel).
    const float len = std::sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    const bool face = geometric || !(len > 1e-6f);
    const float inv = 1.0f / std::max(len, 1e-6f);
    const float nx = face ? lane[kNg][k] : nrm[0] * inv, ny = face ? lane[kNg + 1][k] : nrm[1] * inv, nz = face ? lane[kNg + 2][k] : nrm[2] * inv;
    // Frame::from_normal (Duff et al. 2017).
    const float sign = std::copysign(1.0f, nz);
    const float fa = -1.0f / (sign + nz);
    const float fc = nx * ny * fa;
    const float tx = 1.0f + sign * nx * nx * fa, ty = sign * fc, tz = -sign * nx;
    const float bx = fc, by = sign + ny * ny * fa, bz = -ny;
    float lx, ly, lz;
    concentric_hemisphere(u[0][k], u[1][k], lx, ly, lz);
    const float dx = tx * lx + bx * ly + nx * lz, dy = ty * lx + by * ly + ny * lz, dz = tz * lx + bz * ly + nz * lz;
    // Below the face: occluded by the surface itself (mu = 0), no ray.
    const bool above = dx * lane[kNg][k] + dy * lane[kNg + 1][k] + dz * lane[kNg + 2][k] > 0;
    out.valid[k] = k < count && above ? -1 : 0;
    out.ox[k] = pos[0] + lane[kNg][k] * lane[kOff][k];
    out.oy[k] = pos[1] + lane[kNg + 1][k] * lane[kOff][k];
    out.oz[k] = pos[2] + lane[kNg + 2][k] * lane[kOff][k];
    out.dx[k] = dx, out.dy[k] = dy, out.dz[k] = dz;
  }
}

void make_hemisphere_rays(Vec3 origin, Vec3 n, Vec3 ng, const float (&u)[4][16], int count, TexelRayBatch& out) {
  const Frame f = Frame::from_normal(n);
  for (int k = 0; k < TexelRayBatch::kWidth; ++k) {
    float lx, ly, lz;
    concentric_hemisphere(u[0][k], u[1][k], lx, ly, lz);
    const float dx = f.t.x * lx + f.b.x * ly + f.n.x * lz, dy = f.t.y * lx + f.b.y * ly + f.n.y * lz, dz = f.t.z * lx + f.b.z * ly + f.n.z * lz;
    out.valid[k] = k < count && dx * ng.x + dy * ng.y + dz * ng.z > 0 ? -1 : 0;
    out.ox[k] = origin.x, out.oy[k] = origin.y, out.oz[k] = origin.z;
    out.dx[k] = dx, out.dy[k] = dy, out.dz[k] = dz;
  }
}

}  // namespace ao::detail
