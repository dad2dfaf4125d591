// SPDX-License-Identifier: Apache-2.0
// Storage the SIMD kernels (*_kernel.cpp) read and write: arrays on 64-byte boundaries, so that a
// vector of any target is one aligned load, sized in whole vectors of the widest target.
#pragma once

#include <cstddef>
#include <new>
#include <vector>

namespace ao::simd {

/// Lanes of 32 bits in the widest vector of any target (AVX-512: 16). Arrays the kernels load in
/// whole vectors are padded to a multiple of it.
inline constexpr int kMaxLanes = 16;

/// `n` rounded up to a whole number of the widest vectors.
constexpr int padded(int n) { return (n + kMaxLanes - 1) / kMaxLanes * kMaxLanes; }

/// std::allocator on 64-byte boundaries (a cache line; one AVX-512 vector).
template <class T>
struct Aligned64 {
  using value_type = T;
  Aligned64() = default;
  template <class U>
  Aligned64(const Aligned64<U>&) {}
  T* allocate(std::size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t{64})); }
  void deallocate(T* p, std::size_t) { ::operator delete(p, std::align_val_t{64}); }
  template <class U>
  bool operator==(const Aligned64<U>&) const {
    return true;
  }
};

/// A growable array on 64-byte boundaries.
template <class T>
using AlignedVector = std::vector<T, Aligned64<T>>;

}  // namespace ao::simd
