// SPDX-License-Identifier: Apache-2.0
// The voxelizer's triangles in grid space and what their rasterisation writes besides the grid's
// bits, shared by the voxelizer (voxelize.cpp: projection, bands; winding_solid_internal.h: the
// winding number's walk) and its raster kernel (raster_kernel.cpp), not installed.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

namespace ao::voxel_internal {

// A triangle in grid space: column coordinates and the affine depth attribute.
struct GridTri {
  float x[3], y[3], a[3];
  int j0, j1;  // rows whose centres the bounding box covers
  int fill;    // 0: parity fragment; +1 / -1: open-mesh slab filled towards larger / smaller k;
               // 2: fragment of an open wall's prism (listed, voxelize_into step 4); 3 + s: parity fragment
               // of a fan closing a hole that is not flat, or of a triangle near it, of the solid with
               // holes in slot s (recorded: the winding number is evaluated from there, step 3)
  float slab = 0;  // fill +1 / -1: the slab's length along the column (world units)
};

// A fragment listed rather than toggled: column (i, j), the first voxel beyond it, and the slot of
// the solid with holes whose fan (or triangle near a hole) it belongs to.
struct ColumnHit {
  int i, j, k, tag;
};

// One band of rows' prism faces: per voxel of its columns, how many prisms are entered there minus
// how many are left (prisms face out, so a face's side is the sign of its area in grid space);
// a column is zeroed when first crossed.
struct PrismCounts {
  int r0 = 0, nx = 0, nbits = 0;
  std::unique_ptr<std::int16_t[]> delta;  // (j - r0, i, k)
  std::vector<std::uint8_t> touched;      // (j - r0, i)
  void add(int i, int j, int k, int sign) {
    const std::size_t c = static_cast<std::size_t>(j - r0) * nx + i;
    std::int16_t* d = delta.get() + c * nbits;
    if (!touched[c]) touched[c] = 1, std::fill_n(d, nbits, std::int16_t{0});
    d[k] = static_cast<std::int16_t>(d[k] + sign);
  }
};

}  // namespace ao::voxel_internal
