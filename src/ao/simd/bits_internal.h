// SPDX-License-Identifier: Apache-2.0
// Kernels of the cone method's voxelizer on its bit columns (methods/voxelize.cpp), written once for
// every SIMD target (bits.cpp): the prefix XOR that turns parity toggles into solid voxels
// (Dalla Favera and Celes, sec. III-B: a voxel is inside when an odd number of surfaces lie in front
// of it along its column), and the OR and popcount of the coarse occupancy built from the grid.
#pragma once

#include <cstddef>
#include <cstdint>

namespace ao::simd {

/// Prefix XOR inside each of `n` words: bit k of every word becomes the XOR of its bits 0..k. The
/// carry between the words of one column is the caller's (it runs along a column, not along memory).
void prefix_xor_in_words(std::uint64_t* words, std::size_t n);

/// acc[w] |= row[w] for w in [0, n); returns the number of set bits of row[0..n).
std::size_t or_into_and_count(std::uint64_t* acc, const std::uint64_t* row, std::size_t n);

/// The number of set bits of words[0..n).
std::size_t count_set_bits(const std::uint64_t* words, std::size_t n);

}  // namespace ao::simd
