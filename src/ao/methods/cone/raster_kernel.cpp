// SPDX-License-Identifier: Apache-2.0
// The voxelizer's raster stage (raster_internal.h), compiled once per SIMD target. The loops are
// scalar (one column centre at a time: the tests decide which of two triangles sharing an edge owns
// a centre on it); each target compiles them with its own instructions, none of them fused
// multiply-adds (the layer is compiled with -ffp-contract=off), so every target gives the same grid.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/methods/cone/raster_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <algorithm>
#include <cmath>

#include <hwy/highway.h>

#include "ao/methods/cone/raster_kernel_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

using voxel_internal::ColumnHit;
using voxel_internal::GridTri;
using voxel_internal::PrismCounts;

// Edge function E(x, y) = A x + B y + C of the directed edge p -> q. Swapping p and q negates A,
// B and C exactly (C is an antisymmetric difference of two products), so two triangles sharing
// an edge evaluate exactly opposite values at every column centre, and the tie rule below gives
// a centre on the shared edge to exactly one of them: the voxelization stays watertight.
struct Edge {
  double A, B, C;
  Edge(double px, double py, double qx, double qy) : A(py - qy), B(qx - px), C(px * qy - py * qx) {}
  void negate() { A = -A, B = -B, C = -C; }
  bool inside(double x, double y) const {
    const double e = A * x + B * y + C;
    return e > 0 || (e == 0 && (A > 0 || (A == 0 && B > 0)));
  }
  // Narrows the columns [lo, hi] of row centre y to those that can be inside this edge: the centre
  // x = i + 1/2 where E = 0 is -(B y + C) / A, widened by one column on the open side. The exact test
  // above still decides every centre left, so the grid is the same bits; the span only spares the
  // tests of centres that are surely outside (half of a large triangle's bounding box). The
  // roundings of E and of the crossing are a few ulps of |B y| + |C| (and of |A| x, x <= 2^14),
  // i.e. below 1e-6 columns while |A| > 1e-9 (|B y| + |C|); a flatter edge does not narrow.
  void narrow(double y, double inv_a, int& lo, int& hi) const {
    if (!(std::abs(A) > 1e-9 * (std::abs(B * y) + std::abs(C)))) return;
    const double x = -(B * y + C) * inv_a - 0.5;  // column index i whose centre is on the edge
    if (A > 0) {
      if (x - 1.0 > lo) lo = x - 1.0 > hi ? hi + 1 : static_cast<int>(std::ceil(x - 1.0));
    } else {
      if (x + 1.0 < hi) hi = x + 1.0 < lo ? lo - 1 : static_cast<int>(std::floor(x + 1.0));
    }
  }
};

// Bounding boxes at least this many columns wide (beyond the first) test their rows' spans only.
constexpr int kNarrowColumns = 4;

// Sets bits [b0, b1) of a column (clamped to the column).
inline void set_bits(std::uint64_t* col, int nbits, int b0, int b1) {
  b0 = std::max(b0, 0);
  b1 = std::min(b1, nbits);
  for (int b = b0; b < b1;) {
    const int w = b >> 6, lo = b & 63, n = std::min(64 - lo, b1 - b);
    col[w] |= (n == 64 ? ~std::uint64_t{0} : ((std::uint64_t{1} << n) - 1)) << lo;
    b += n;
  }
}

// Rasterises one triangle's rows [r0, r1]. A parity fragment toggles one bit (XOR to the end after
// the scan), and is listed in `hits` when it belongs to a fan over a hole that is not flat; a slab
// fragment of an open mesh ORs the voxels within `slab` (world units) behind it; a prism's fragment
// is counted in `prisms`. Returns fragments.
// kListed: the triangle's fragments are listed (fill 2 or >= 3), a separate instantiation so that
// the plain parity loop carries no test for it.
template <bool kPerspective, bool kListed>
std::size_t rasterise(const GridTri& t, int r0, int r1, VoxelGrid& g, float slab, std::vector<ColumnHit>& hits, PrismCounts* prisms) {
  const double x0 = t.x[0], y0 = t.y[0];
  const double area2 = (double(t.x[1]) - x0) * (double(t.y[2]) - y0) - (double(t.x[2]) - x0) * (double(t.y[1]) - y0);
  if (area2 == 0) return 0;  // edge-on: no column centre lies inside
  const float xmin = std::min({t.x[0], t.x[1], t.x[2]}), xmax = std::max({t.x[0], t.x[1], t.x[2]});
  const int i0 = std::max(0, static_cast<int>(std::ceil(xmin - 0.5f)));
  const int i1 = std::min(g.nx - 1, static_cast<int>(std::floor(xmax - 0.5f)));
  if (i0 > i1 || r0 > r1) return 0;  // no column centre in the box (a small triangle between centres)
  Edge e[3] = {{t.x[0], t.y[0], t.x[1], t.y[1]}, {t.x[1], t.y[1], t.x[2], t.y[2]}, {t.x[2], t.y[2], t.x[0], t.y[0]}};
  if (area2 < 0)
    for (Edge& ed : e) ed.negate();  // back faces count as much as front faces (sec. III-B)
  // Plane of the attribute over the column coordinates.
  const double da1 = double(t.a[1]) - t.a[0], da2 = double(t.a[2]) - t.a[0];
  const double dadx = (da1 * (double(t.y[2]) - y0) - da2 * (double(t.y[1]) - y0)) / area2;
  const double dady = (da2 * (double(t.x[1]) - x0) - da1 * (double(t.x[2]) - x0)) / area2;
  const int nbits = g.depth_bits, words = g.words;
  // A box a few columns wide has no centres to spare worth the spans' arithmetic (most triangles
  // of a detailed mesh at 512 columns).
  const bool narrow = i1 - i0 >= kNarrowColumns;
  double inv_a[3] = {0, 0, 0};
  if (narrow)
    for (int k = 0; k < 3; ++k) inv_a[k] = 1.0 / e[k].A;
  std::size_t fragments = 0;
  for (int j = r0; j <= r1; ++j) {
    const double yc = j + 0.5;
    std::uint64_t* row = g.bits.data() + static_cast<std::size_t>(j) * g.nx * words;
    int span_lo = i0, span_hi = i1;
    if (narrow)
      for (int k = 0; k < 3; ++k) e[k].narrow(yc, inv_a[k], span_lo, span_hi);
    for (int i = span_lo; i <= span_hi; ++i) {
      const double xc = i + 0.5;
      if (!(e[0].inside(xc, yc) && e[1].inside(xc, yc) && e[2].inside(xc, yc))) continue;
      const double a = t.a[0] + dadx * (xc - x0) + dady * (yc - y0);
      double k;  // continuous voxel coordinate of the fragment along the column
      if constexpr (kPerspective) {
        // eq. 2: z_GridIndex = (z - z_nearest) / (z_far - z_nearest), scaled to depth_bits.
        const std::size_t c = static_cast<std::size_t>(j) * g.nx + i;
        k = (1.0 / a - g.z_near[c]) * g.voxels_per_unit[c];
      } else {
        k = a;
      }
      if (t.fill == 1 || t.fill == -1) {
        double thickness;  // slab thickness in voxels along the column
        const float length = t.slab > 0.0f ? t.slab : slab;
        if constexpr (kPerspective) thickness = length * g.voxels_per_unit[static_cast<std::size_t>(j) * g.nx + i];
        else thickness = length / g.voxel_size.z;
        const double lo = t.fill > 0 ? k : k - thickness, hi = t.fill > 0 ? k + thickness : k;
        const double b0 = std::clamp(std::ceil(lo - 0.5), 0.0, double(nbits)), b1 = std::clamp(std::ceil(hi - 0.5), 0.0, double(nbits));
        set_bits(row + static_cast<std::size_t>(i) * words, nbits, static_cast<int>(b0), static_cast<int>(b1));
        ++fragments;
        continue;
      }
      // The fragment flips every voxel whose centre (b + 0.5) lies beyond it.
      const double first = std::ceil(k - 0.5);
      if (first >= nbits) continue;
      const int b = first <= 0 ? 0 : static_cast<int>(first);
      ++fragments;
      if constexpr (kListed) {
        if (t.fill == 2) {
          prisms->add(i, j, b, area2 > 0 ? 1 : -1);
          continue;
        }
        hits.push_back({i, j, b, t.fill - 3});
      }
      row[static_cast<std::size_t>(i) * words + (b >> 6)] ^= std::uint64_t{1} << (b & 63);
    }
  }
  return fragments;
}

std::size_t RasteriseTriangles(const GridTri* tris, const std::uint32_t* index, std::size_t n, bool perspective, int r0, int r1, VoxelGrid& g,
                               float slab, std::vector<ColumnHit>& hits, PrismCounts* prisms) {
  std::size_t f = 0;
  for (std::size_t q = 0; q < n; ++q) {
    const GridTri& t = tris[index[q]];
    const int lo = std::max(r0, t.j0), hi = std::min(r1, t.j1);
    const bool listed = t.fill == 2 || t.fill >= 3;
    if (perspective)
      f += listed ? rasterise<true, true>(t, lo, hi, g, slab, hits, prisms) : rasterise<true, false>(t, lo, hi, g, slab, hits, prisms);
    else
      f += listed ? rasterise<false, true>(t, lo, hi, g, slab, hits, prisms) : rasterise<false, false>(t, lo, hi, g, slab, hits, prisms);
  }
  return f;
}

}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ao::simd {

HWY_EXPORT(RasteriseTriangles);

std::size_t rasterise_triangles(const voxel_internal::GridTri* tris, const std::uint32_t* index, std::size_t n, bool perspective, int r0, int r1,
                                VoxelGrid& g, float slab, std::vector<voxel_internal::ColumnHit>& hits, voxel_internal::PrismCounts* prisms) {
  return HWY_DYNAMIC_DISPATCH(RasteriseTriangles)(tris, index, n, perspective, r0, r1, g, slab, hits, prisms);
}

}  // namespace ao::simd
#endif
