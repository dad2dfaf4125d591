// SPDX-License-Identifier: Apache-2.0
// The voxel grid's column scan and coarse occupancy (voxel_grid_internal.h): the last stages of
// the parity voxelization (Eisemann & Decoret 2008; Dalla Favera & Celes 2012, sec. III-B) and the
// empty-space skipping masks the cone tracer reads (voxelize.h).
#include "ao/methods/cone/voxel_grid_internal.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "ao/simd/bits_internal.h"

namespace ao {

std::size_t VoxelGrid::count_set() const {
  return simd::count_set_bits(bits.data(), bits.size());
}

namespace voxel_internal {

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

}  // namespace voxel_internal

}  // namespace ao
