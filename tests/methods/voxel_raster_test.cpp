// SPDX-License-Identifier: Apache-2.0
// The voxelizer's raster stage (methods/cone/raster_kernel.cpp) tests only the column centres of each row's span
// between the triangle's edges (widened by a column), not the whole bounding box. Its grid must be
// the one a test of every centre of the box gives: the same edge functions and tie rule, evaluated
// here over the whole box, on triangles that stress the span's arithmetic (huge and tiny, far
// outside the grid, nearly horizontal edges, edges through column centres).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "ao/methods/cone/voxelize.h"
#include "ao/methods/cone/raster_kernel_internal.h"

namespace ao {
namespace {

using voxel_internal::ColumnHit;
using voxel_internal::GridTri;

VoxelGrid empty_grid(int n, int bits) {
  VoxelGrid g;
  g.nx = g.ny = n;
  g.depth_bits = bits;
  g.words = (bits + 63) / 64;
  g.voxel_size = {1, 1, 1};
  g.bits.assign(static_cast<std::size_t>(n) * n * g.words, 0);
  return g;
}

// Every column centre of the bounding box, tested against the three edges with the raster's rule
// (E > 0, or E = 0 on an edge whose normal points to +x, or to +y when vertical), each triangle's
// fragment toggling the bits from its first voxel on, as rasterise_triangles does for fill 0.
void toggle_full_box(const GridTri& t, VoxelGrid& g) {
  const double x0 = t.x[0], y0 = t.y[0];
  const double area2 = (double(t.x[1]) - x0) * (double(t.y[2]) - y0) - (double(t.x[2]) - x0) * (double(t.y[1]) - y0);
  if (area2 == 0) return;
  double A[3], B[3], C[3];
  for (int k = 0; k < 3; ++k) {
    const double px = t.x[k], py = t.y[k], qx = t.x[(k + 1) % 3], qy = t.y[(k + 1) % 3];
    const double s = area2 < 0 ? -1.0 : 1.0;
    A[k] = s * (py - qy), B[k] = s * (qx - px), C[k] = s * (px * qy - py * qx);
  }
  const double da1 = double(t.a[1]) - t.a[0], da2 = double(t.a[2]) - t.a[0];
  const double dadx = (da1 * (double(t.y[2]) - y0) - da2 * (double(t.y[1]) - y0)) / area2;
  const double dady = (da2 * (double(t.x[1]) - x0) - da1 * (double(t.x[2]) - x0)) / area2;
  const int i0 = std::max(0, static_cast<int>(std::ceil(std::min({t.x[0], t.x[1], t.x[2]}) - 0.5f)));
  const int i1 = std::min(g.nx - 1, static_cast<int>(std::floor(std::max({t.x[0], t.x[1], t.x[2]}) - 0.5f)));
  for (int j = std::max(0, t.j0); j <= std::min(g.ny - 1, t.j1); ++j)
    for (int i = i0; i <= i1; ++i) {
      const double xc = i + 0.5, yc = j + 0.5;
      bool in = true;
      for (int k = 0; k < 3 && in; ++k) {
        const double e = A[k] * xc + B[k] * yc + C[k];
        in = e > 0 || (e == 0 && (A[k] > 0 || (A[k] == 0 && B[k] > 0)));
      }
      if (!in) continue;
      const double first = std::ceil(t.a[0] + dadx * (xc - x0) + dady * (yc - y0) - 0.5);
      if (first >= g.depth_bits) continue;
      const int b = first <= 0 ? 0 : static_cast<int>(first);
      g.bits[(static_cast<std::size_t>(j) * g.nx + i) * g.words + (b >> 6)] ^= std::uint64_t{1} << (b & 63);
    }
}

GridTri grid_tri(float ax, float ay, float bx, float by, float cx, float cy, int n) {
  GridTri t{{ax, bx, cx}, {ay, by, cy}, {3.0f, 40.0f, 17.5f}, 0, 0, 0};
  const float lo = std::min({ay, by, cy}), hi = std::max({ay, by, cy});
  t.j0 = std::max(0, static_cast<int>(std::ceil(std::max(lo, -1e6f) - 0.5f)));
  t.j1 = std::min(n - 1, static_cast<int>(std::floor(std::min(hi, 1e6f) - 0.5f)));
  return t;
}

TEST(Voxelize, RasterSpanTestsTheCentresTheWholeBoxWould) {
  constexpr int kN = 48, kBits = 64;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> in_grid(-4.0f, kN + 4.0f), unit(0.0f, 1.0f);
  std::vector<GridTri> tris;
  for (int k = 0; k < 3000; ++k) {
    const float s = k % 3 == 0 ? 1.0f : k % 3 == 1 ? 0.05f : 8.0f;  // mid-size, slivers, large
    const float ax = in_grid(rng), ay = in_grid(rng);
    tris.push_back(grid_tri(ax, ay, ax + s * (in_grid(rng) - kN / 2), ay + s * (in_grid(rng) - kN / 2), ax + s * (in_grid(rng) - kN / 2),
                            ay + s * (in_grid(rng) - kN / 2), kN));
  }
  // Vertices far outside the grid (an eye grid's triangle near the camera plane), nearly
  // horizontal edges, and edges through column centres.
  for (float far : {1e3f, 1e5f, 1e7f, 3e8f}) {
    tris.push_back(grid_tri(-far, -far * 0.5f, far, 20.3f, 10.1f, far, kN));
    tris.push_back(grid_tri(-far, 24.5f, far, 24.5f + 1e-6f * far, 24.0f, far, kN));
  }
  for (int k = 0; k < 200; ++k) {
    const float y = static_cast<float>(k % kN) + 0.5f, x = static_cast<float>(k % 17) + 0.5f;
    tris.push_back(grid_tri(x, y, x + 20.0f, y + unit(rng) * 1e-5f, x + 3.0f, y + 12.0f, kN));  // an edge through centres, nearly flat
    tris.push_back(grid_tri(x, y, x + 7.0f, y + 7.0f, x - 5.0f, y + 30.0f, kN));                // an edge along the centres' diagonal
  }
  VoxelGrid spans = empty_grid(kN, kBits), full = empty_grid(kN, kBits);
  std::vector<std::uint32_t> index(tris.size());
  for (std::uint32_t k = 0; k < index.size(); ++k) index[k] = k;
  std::vector<ColumnHit> hits;
  const std::size_t fragments = simd::rasterise_triangles(tris.data(), index.data(), tris.size(), false, 0, kN - 1, spans, 0.0f, hits, nullptr);
  for (const GridTri& t : tris) toggle_full_box(t, full);
  EXPECT_GT(fragments, 10000u);
  std::size_t differ = 0;
  for (std::size_t w = 0; w < spans.bits.size(); ++w) differ += spans.bits[w] != full.bits[w];
  EXPECT_EQ(differ, 0u) << "columns whose bits differ from the whole box's tests";
}

}  // namespace
}  // namespace ao
