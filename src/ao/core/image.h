// SPDX-License-Identifier: Apache-2.0
// Image<T>: an owning 2-D array of pixels, row-major, (0,0) at the top left.
// ImageView<T>: a non-owning view of one, what kernels take.
#pragma once

#include <cstddef>
#include <memory>
#include <new>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "ao/core/error.h"

namespace ao {

template <class T>
struct ImageView {
  T* data = nullptr;
  int width = 0;
  int height = 0;

  T& operator()(int x, int y) const {
    AO_ASSERT(x >= 0 && x < width && y >= 0 && y < height);
    return data[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)];
  }
  std::span<T> row(int y) const { return {data + static_cast<std::size_t>(y) * width, static_cast<std::size_t>(width)}; }
  std::size_t size() const { return static_cast<std::size_t>(width) * height; }
};

namespace detail {
/// Storage for `bytes` bytes of pixels, released with free_pixels(p, bytes). It starts on a cache
/// line (64 bytes; malloc gives 16), so rows whose size is a multiple of 64 bytes cover whole
/// lines, which streamed (non-temporal) stores write without reading and without two threads
/// sharing a line at a tile seam. Blocks of 2 MiB and more start on a 2 MiB boundary and are
/// advised to the kernel as transparent huge pages (Linux, madvise): a fresh 1280 x 720 G-buffer
/// then takes ~1,000 page faults (the last part under 2 MiB of a channel stays on 4 KiB) not 7,200.
void* allocate_pixels(std::size_t bytes);
void free_pixels(void* p, std::size_t bytes) noexcept;

/// An allocator whose containers leave new pixels uninitialised, so that
/// Image::resize does not write (and page in) memory the caller is about to overwrite. Storage
/// comes from allocate_pixels.
template <class T>
struct DefaultInitAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() = default;
  template <class U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) { return static_cast<T*>(allocate_pixels(n * sizeof(T))); }
  void deallocate(T* p, std::size_t n) noexcept { free_pixels(p, n * sizeof(T)); }
  // Pixel types (float, Vec3, ...) are trivially copyable aggregates: implicit-lifetime types,
  // whose objects exist in the allocated storage without a constructor call (C++20 [intro.object]),
  // so even their default member initialisers are skipped. Others are default-initialised.
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    if constexpr (!(std::is_trivially_copyable_v<U> && std::is_trivially_destructible_v<U>)) ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    std::allocator_traits<std::allocator<T>>::construct(static_cast<std::allocator<T>&>(*this), p, std::forward<Args>(args)...);
  }
};
}  // namespace detail

template <class T>
class Image {
 public:
  Image() = default;
  Image(int width, int height, T fill = T{})
      : width_(width), height_(height), pixels_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), fill) {
    AO_ASSERT(width >= 0 && height >= 0);
  }

  /// Gives the image a new size, keeping its storage when that is large enough: a caller that
  /// renders every frame then touches no fresh pages. Pixel values are unspecified afterwards
  /// (new pixels of trivial types are not even written, so a kernel that fills every pixel in
  /// parallel pays for the fresh pages in parallel, once).
  void resize(int width, int height) {
    AO_ASSERT(width >= 0 && height >= 0);
    width_ = width, height_ = height;
    pixels_.resize(static_cast<std::size_t>(width) * height);
  }

  int width() const { return width_; }
  int height() const { return height_; }
  std::size_t size() const { return pixels_.size(); }
  bool empty() const { return pixels_.empty(); }

  T& operator()(int x, int y) { return view()(x, y); }
  const T& operator()(int x, int y) const { return view()(x, y); }
  T& operator[](std::size_t i) { return pixels_[i]; }
  const T& operator[](std::size_t i) const { return pixels_[i]; }

  T* data() { return pixels_.data(); }
  const T* data() const { return pixels_.data(); }
  std::span<T> pixels() { return pixels_; }
  std::span<const T> pixels() const { return pixels_; }

  ImageView<T> view() { return {pixels_.data(), width_, height_}; }
  ImageView<const T> view() const { return {pixels_.data(), width_, height_}; }

 private:
  int width_ = 0;
  int height_ = 0;
  std::vector<T, detail::DefaultInitAllocator<T>> pixels_;
};

}  // namespace ao
