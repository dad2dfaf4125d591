// Image<T>: an owning 2-D array of pixels, row-major, (0,0) at the top left.
// ImageView<T>: a non-owning view of one, what kernels take.
#pragma once

#include <cstddef>
#include <span>
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
    return data[static_cast<std::size_t>(y) * width + x];
  }
  std::span<T> row(int y) const { return {data + static_cast<std::size_t>(y) * width, static_cast<std::size_t>(width)}; }
  std::size_t size() const { return static_cast<std::size_t>(width) * height; }
};

template <class T>
class Image {
 public:
  Image() = default;
  Image(int width, int height, T fill = T{})
      : width_(width), height_(height), pixels_(static_cast<std::size_t>(width) * height, fill) {
    AO_ASSERT(width >= 0 && height >= 0);
  }

  /// Gives the image a new size, keeping its storage when that is large enough: a caller that
  /// renders every frame then touches no fresh pages. Pixel values are unspecified afterwards.
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
  std::vector<T> pixels_;
};

}  // namespace ao
