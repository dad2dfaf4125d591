// SPDX-License-Identifier: Apache-2.0
// Generalized winding numbers (Jacobson et al. 2013), fast by Barill et al. 2018; see
// winding_number.h.
#include "ao/methods/cone/winding_number.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "ao/core/error.h"

namespace ao {

namespace {

constexpr std::uint32_t kLeafSize = 8;  // triangles summed exactly per leaf
constexpr double kInv4Pi = 0.25 / 3.14159265358979323846;

struct D3 {
  double x, y, z;
};
D3 d3(Vec3 v) { return {v.x, v.y, v.z}; }
D3 sub(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
double ddot(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
D3 dcross(D3 a, D3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double dlen(D3 a) { return std::sqrt(ddot(a, a)); }

}  // namespace

WindingNumber::WindingNumber(std::span<const Vec3> positions, std::span<const std::uint32_t> indices, double beta) {
  if (!(beta > 1.0)) throw InputError("winding number: beta must be > 1, got " + std::to_string(beta));
  beta2_ = beta * beta;
  std::vector<Tri> tris;
  std::vector<Vec3> centroid;
  std::vector<float> area;
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    const Tri tri{positions[indices[t]], positions[indices[t + 1]], positions[indices[t + 2]]};
    const float a = 0.5f * length(cross(tri.b - tri.a, tri.c - tri.a));
    if (!(a > 0.0f)) continue;  // a zero-area triangle subtends no solid angle
    tris.push_back(tri);
    centroid.push_back((tri.a + tri.b + tri.c) * (1.0f / 3.0f));
    area.push_back(a);
  }
  if (tris.empty()) return;
  std::vector<std::uint32_t> order(tris.size());
  std::iota(order.begin(), order.end(), 0u);
  nodes_.reserve(2 * tris.size() / kLeafSize + 2);
  build(order, 0, static_cast<std::uint32_t>(tris.size()), tris, centroid, area);
  tris_.resize(tris.size());
  for (std::size_t i = 0; i < order.size(); ++i) tris_[i] = tris[order[i]];  // leaves index into tris_ in `order`
}

// Builds the node over order[first, first + count) (reordering that range) and returns its index.
std::uint32_t WindingNumber::build(std::vector<std::uint32_t>& order, std::uint32_t first, std::uint32_t count, const std::vector<Tri>& tris,
                                   const std::vector<Vec3>& centroid, const std::vector<float>& area) {
  const std::uint32_t id = static_cast<std::uint32_t>(nodes_.size());
  nodes_.emplace_back();
  // Expansion coefficients: t1 = sum a n, p~ = area-weighted centroid, t2 = sum a (c - p~) n^T.
  // Both are the exact integrals over the triangles (the integral of p over a triangle is its area
  // times its centroid), so the expansion's only error is its truncation.
  double sa = 0, cx = 0, cy = 0, cz = 0;
  D3 t1{0, 0, 0};
  Bounds3 box;
  for (std::uint32_t k = first; k < first + count; ++k) {
    const std::uint32_t i = order[k];
    const double a = area[i];
    sa += a, cx += a * centroid[i].x, cy += a * centroid[i].y, cz += a * centroid[i].z;
    const D3 n2 = dcross(sub(d3(tris[i].b), d3(tris[i].a)), sub(d3(tris[i].c), d3(tris[i].a)));  // 2 a n
    t1 = {t1.x + 0.5 * n2.x, t1.y + 0.5 * n2.y, t1.z + 0.5 * n2.z};
    box.extend(centroid[i]);
  }
  const D3 p{cx / sa, cy / sa, cz / sa};
  double t2[9] = {}, t3[18] = {};
  double radius2 = 0;
  Bounds3 vertices;
  for (std::uint32_t k = first; k < first + count; ++k) {
    const std::uint32_t i = order[k];
    const D3 n2 = dcross(sub(d3(tris[i].b), d3(tris[i].a)), sub(d3(tris[i].c), d3(tris[i].a)));
    const double a = area[i], len = dlen(n2);
    const double nv[3] = {n2.x / len, n2.y / len, n2.z / len};  // unit normal
    // Vertices and centroid relative to p~: the integral of p' p'^T over a triangle is
    // (a / 12) (sum of w w^T over its vertices w + (sum w)(sum w)^T).
    double w[3][3];
    for (int v = 0; v < 3; ++v) {
      const Vec3 corner = v == 0 ? tris[i].a : v == 1 ? tris[i].b : tris[i].c;
      vertices.extend(corner);
      w[v][0] = double(corner.x) - p.x, w[v][1] = double(corner.y) - p.y, w[v][2] = double(corner.z) - p.z;
      radius2 = std::max(radius2, w[v][0] * w[v][0] + w[v][1] * w[v][1] + w[v][2] * w[v][2]);
    }
    const double c[3] = {(w[0][0] + w[1][0] + w[2][0]) / 3, (w[0][1] + w[1][1] + w[2][1]) / 3, (w[0][2] + w[1][2] + w[2][2]) / 3};
    for (int r = 0; r < 3; ++r)
      for (int col = 0; col < 3; ++col) t2[3 * r + col] += a * c[r] * nv[col];
    double m[3][3];
    for (int r = 0; r < 3; ++r)
      for (int col = 0; col < 3; ++col) {
        double s = 9.0 * c[r] * c[col];
        for (const auto& wv : w) s += wv[r] * wv[col];
        m[r][col] = a / 12.0 * s;
      }
    for (int j = 0; j < 3; ++j)
      for (int kk = 0, q = 0; kk < 3; ++kk)
        for (int l = kk; l < 3; ++l, ++q) t3[6 * j + q] += nv[j] * m[kk][l];
  }
  {
    Node& n = nodes_[id];
    n.centre = {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)};
    // Rounded up so that the far-field test stays conservative after the conversion to float.
    n.radius = static_cast<float>(std::sqrt(radius2)) * (1.0f + 1e-6f);
    n.t1 = {static_cast<float>(t1.x), static_cast<float>(t1.y), static_cast<float>(t1.z)};
    for (int k = 0; k < 9; ++k) n.t2[k] = static_cast<float>(t2[k]);
    for (int k = 0; k < 18; ++k) n.t3[k] = static_cast<float>(t3[k]);
    n.lo = vertices.lo;
    n.hi = vertices.hi;
  }
  if (count <= kLeafSize) {
    nodes_[id].first = first;
    nodes_[id].count = count;
    return id;
  }
  // Median split of the centroids along the box's longest axis.
  const Vec3 e = box.extent();
  const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
  const std::uint32_t half = count / 2;
  std::nth_element(order.begin() + first, order.begin() + first + half, order.begin() + first + count,
                   [&](std::uint32_t a, std::uint32_t b) { return centroid[a][axis] < centroid[b][axis]; });
  const std::uint32_t left = build(order, first, half, tris, centroid, area);
  const std::uint32_t right = build(order, first + half, count - half, tris, centroid, area);
  nodes_[id].left = left;
  nodes_[id].right = right;
  return id;
}

// Signed solid angle of triangle t at q (Van Oosterom & Strackee 1983):
// tan(Omega / 2) = det[a b c] / (|a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|), a = A - q, ...
// det > 0 when q is behind the triangle. A point in the triangle's plane gets 0: off the triangle
// that is its solid angle, on it the mean of the limits from its two sides (+-2 pi), so that w on
// a surface is the mean of w on its two sides.
double WindingNumber::solid_angle(const Tri& t, Vec3 q) {
  const D3 qd = d3(q);
  const D3 a = sub(d3(t.a), qd), b = sub(d3(t.b), qd), c = sub(d3(t.c), qd);
  const double det = ddot(a, dcross(b, c));
  if (det == 0.0) return 0.0;
  const double la = dlen(a), lb = dlen(b), lc = dlen(c);
  const double den = la * lb * lc + ddot(a, b) * lc + ddot(a, c) * lb + ddot(b, c) * la;
  return 2.0 * std::atan2(det, den);
}

namespace {

// Closest point of triangle abc to p (Ericson, "Real-Time Collision Detection", sec. 5.1.5).
D3 closest_on_triangle(D3 p, D3 a, D3 b, D3 c) {
  const D3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  const double d1 = ddot(ab, ap), d2 = ddot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const D3 bp = sub(p, b);
  const double d3 = ddot(ab, bp), d4 = ddot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return {a.x + v * ab.x, a.y + v * ab.y, a.z + v * ab.z};
  }
  const D3 cp = sub(p, c);
  const double d5 = ddot(ab, cp), d6 = ddot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return {a.x + w * ac.x, a.y + w * ac.y, a.z + w * ac.z};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {b.x + w * (c.x - b.x), b.y + w * (c.y - b.y), b.z + w * (c.z - b.z)};
  }
  const double denom = 1.0 / (va + vb + vc), v = vb * denom, w = vc * denom;
  return {a.x + ab.x * v + ac.x * w, a.y + ab.y * v + ac.y * w, a.z + ab.z * v + ac.z * w};
}

}  // namespace

double WindingNumber::signed_distance(Vec3 q) const {
  if (nodes_.empty()) return std::numeric_limits<double>::infinity();
  const D3 qd = d3(q);
  double best2 = std::numeric_limits<double>::infinity(), side = 0;
  // Squared distance from q to a node's box: no point of the node is nearer.
  const auto gap2 = [&](const Node& n) {
    const double dx = std::max({double(n.lo.x) - q.x, 0.0, double(q.x) - n.hi.x});
    const double dy = std::max({double(n.lo.y) - q.y, 0.0, double(q.y) - n.hi.y});
    const double dz = std::max({double(n.lo.z) - q.z, 0.0, double(q.z) - n.hi.z});
    return dx * dx + dy * dy + dz * dz;
  };
  std::uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (gap2(n) >= best2) continue;
    if (n.count == 0) {
      // The nearer child last, so that it is searched first and tightens the bound.
      const bool left_first = gap2(nodes_[n.left]) <= gap2(nodes_[n.right]);
      stack[top++] = left_first ? n.right : n.left;
      stack[top++] = left_first ? n.left : n.right;
      continue;
    }
    for (std::uint32_t i = n.first; i < n.first + n.count; ++i) {
      const Tri& t = tris_[i];
      const D3 a = d3(t.a), b = d3(t.b), c = d3(t.c);
      const D3 e = sub(qd, closest_on_triangle(qd, a, b, c));
      const double d2 = ddot(e, e);
      if (d2 < best2) {
        best2 = d2;
        side = -ddot(dcross(sub(b, a), sub(c, a)), sub(qd, a));  // > 0 behind the triangle
      }
    }
  }
  return side > 0 ? std::sqrt(best2) : side < 0 ? -std::sqrt(best2) : 0.0;
}

WindingNumber::Hit WindingNumber::first_hit(Vec3 o, Vec3 d, float t_min, float t_max) const {
  Hit best{std::numeric_limits<float>::infinity(), 0};
  // A direction that is not finite (a degenerate face's normal) meets nothing; its NaNs would
  // otherwise open every node.
  if (nodes_.empty() || !(t_max > t_min) || !std::isfinite(d.x + d.y + d.z)) return best;
  const Vec3 inv{1.0f / d.x, 1.0f / d.y, 1.0f / d.z};  // +-infinity along an axis d does not move on
  float limit = t_max;
  // The ray's entry into a node's box (slabs), or +infinity when it misses it within (t_min, limit].
  const auto enter = [&](const Node& n) {
    float t0 = t_min, t1 = limit;
    const float lo[3] = {n.lo.x, n.lo.y, n.lo.z}, hi[3] = {n.hi.x, n.hi.y, n.hi.z}, oo[3] = {o.x, o.y, o.z}, ii[3] = {inv.x, inv.y, inv.z};
    for (int a = 0; a < 3; ++a) {
      float u = (lo[a] - oo[a]) * ii[a], v = (hi[a] - oo[a]) * ii[a];
      if (u > v) std::swap(u, v);
      // NaN (0 x infinity: the origin on a face of the box, d parallel to it) leaves the bound as it is.
      t0 = u > t0 ? u : t0;
      t1 = v < t1 ? v : t1;
    }
    return t0 <= t1 ? t0 : std::numeric_limits<float>::infinity();
  };
  std::uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (!(enter(n) <= limit)) continue;
    if (n.count == 0) {
      const float tl = enter(nodes_[n.left]), tr = enter(nodes_[n.right]);
      // The nearer child last, so that it is searched first and shortens the ray.
      if (tl <= tr) {
        if (tr <= limit) stack[top++] = n.right;
        if (tl <= limit) stack[top++] = n.left;
      } else {
        if (tl <= limit) stack[top++] = n.left;
        if (tr <= limit) stack[top++] = n.right;
      }
      continue;
    }
    for (std::uint32_t i = n.first; i < n.first + n.count; ++i) {
      const Tri& tr = tris_[i];
      const Vec3 e1 = tr.b - tr.a, e2 = tr.c - tr.a, pv = cross(d, e2);
      const float det = dot(e1, pv);
      if (det == 0.0f) continue;
      const float inv_det = 1.0f / det;
      const Vec3 s = o - tr.a;
      const float u = dot(s, pv) * inv_det;
      if (u < 0.0f || u > 1.0f) continue;
      const Vec3 qv = cross(s, e1);
      const float v = dot(d, qv) * inv_det;
      if (v < 0.0f || u + v > 1.0f) continue;
      const float t = dot(e2, qv) * inv_det;
      if (t > t_min && t <= limit) {
        limit = t;
        // det = -dot(d, e1 x e2): positive when d runs against the front normal (met from the front).
        best = {t, det > 0.0f ? -1 : 1};
      }
    }
  }
  return best;
}

// The same in single precision, for the hierarchy's leaves: its rounding (1e-7 relative per
// triangle) is far below the far field's truncation error.
double WindingNumber::solid_angle_float(const Tri& t, Vec3 q) {
  const Vec3 a = t.a - q, b = t.b - q, c = t.c - q;
  const float det = dot(a, cross(b, c));
  if (det == 0.0f) return 0.0;
  const float la = length(a), lb = length(b), lc = length(c);
  const float den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
  return 2.0 * static_cast<double>(std::atan2(det, den));
}

double WindingNumber::exact(Vec3 q) const {
  double sum = 0;
  for (const Tri& t : tris_) sum += solid_angle(t, q);
  return sum * kInv4Pi;
}

double WindingNumber::operator()(Vec3 q) const {
  if (nodes_.empty()) return 0.0;
  double sum = 0;
  std::uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    const D3 x{double(n.centre.x) - q.x, double(n.centre.y) - q.y, double(n.centre.z) - q.z};  // x~ = p~ - q
    const double r2 = ddot(x, x);
    if (r2 > beta2_ * double(n.radius) * n.radius) {
      // Far field: the solid angle is the integral of n.g(p - q) over the triangles, with
      // g(x) = x / |x|^3, expanded about x = p~ - q:
      //   t1.g + sum_jk dg_j/dx_k t2_kj + 1/2 sum_jkl d2g_j/dx_k dx_l t3_jkl, where
      //   dg_j/dx_k = delta_jk / r^3 - 3 x_j x_k / r^5 and
      //   d2g_j/dx_k dx_l = -3 (delta_jk x_l + delta_jl x_k + delta_kl x_j) / r^5 + 15 x_j x_k x_l / r^7.
      const double inv_r2 = 1.0 / r2, inv_r = std::sqrt(inv_r2), inv_r3 = inv_r * inv_r2, inv_r5 = inv_r3 * inv_r2;
      const double xv[3] = {x.x, x.y, x.z};
      double xtx = 0;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) xtx += xv[r] * double(n.t2[3 * r + c]) * xv[c];
      const double trace = double(n.t2[0]) + n.t2[4] + n.t2[8];
      // Third order, with t3 symmetric in k, l (stored for k <= l): u_l = sum_j t3_jjl,
      // v_j = sum_k t3_jkk, and x.x.x.t3.
      static constexpr int kIndex[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};
      double xu = 0, xv3 = 0, xxx = 0;
      for (int j = 0; j < 3; ++j) {
        const float* tj = n.t3.data() + 6 * j;
        double u = 0, xkl = 0;
        for (int l = 0; l < 3; ++l) u += double(n.t3[6 * l + kIndex[l][j]]);
        xu += xv[j] * u;
        xv3 += xv[j] * (double(tj[0]) + tj[3] + tj[5]);
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 3; ++l) xkl += xv[k] * xv[l] * double(tj[kIndex[k][l]]);
        xxx += xv[j] * xkl;
      }
      const double third = 0.5 * (-3.0 * inv_r5 * (2.0 * xu + xv3) + 15.0 * inv_r5 * inv_r2 * xxx);
      sum += (double(n.t1.x) * x.x + double(n.t1.y) * x.y + double(n.t1.z) * x.z + trace) * inv_r3 - 3.0 * xtx * inv_r5 + third;
    } else if (n.count > 0) {
      for (std::uint32_t i = n.first; i < n.first + n.count; ++i) sum += solid_angle_float(tris_[i], q);
    } else {
      stack[top++] = n.left;
      stack[top++] = n.right;
    }
  }
  return sum * kInv4Pi;
}

}  // namespace ao
