// SPDX-License-Identifier: Apache-2.0
#include "ao/methods/filters/interleave.h"

#include <array>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "ao/core/error.h"
#include "ao/core/parallel.h"
#include "ao/methods/filters/filters_kernel_internal.h"
#include "ao/simd/depth_plane.h"

namespace ao {

float effective_depth_limit(const InterleaveOptions& o, float radius) { return o.filter_depth_limit > 0 ? o.filter_depth_limit : 0.25f * radius; }

namespace {

// The 4x4 window is not separable (neighbours are skipped by their depth difference to the CENTRE
// pixel), so it runs as one pass of 16 taps per pixel: simd::box_filter_rows, in bands of 8 rows.
// Sources are rows of S interleaved floats per pixel (S = 1: float planes; S = 3: a Vec3 RGB image,
// filtered in place of planes), up to 4 filtered together so that each tap's depth test serves all.
void box_filter(std::span<const float* const> src, std::span<float* const> dst, int stride, const GBuffer& g, float limit,
                const Image<float>* depth_image) {
  Image<float> own;
  if (!depth_image) depth_plane(g, own);
  const simd::BoxFilterImage image{src.data(), dst.data(), static_cast<int>(src.size()), stride, depth_image ? depth_image->data() : own.data(),
                                   g.object_id.data(), g.width(), g.height()};
  tbb::parallel_for(
      tbb::blocked_range<int>(0, g.height(), 8), [&](const tbb::blocked_range<int>& r) { simd::box_filter_rows(image, limit, r.begin(), r.end()); },
      tbb::simple_partitioner());
}

void check_size(const GBuffer& g, int w, int h) {
  if (w != g.width() || h != g.height()) throw InputError("depth_aware_box_filter: the image must have the G-buffer's size");
}

}  // namespace

Image<float> depth_aware_box_filter(const Image<float>& image, const GBuffer& g, float depth_limit, const Image<float>* depth) {
  check_size(g, image.width(), image.height());
  Image<float> out;
  out.resize(image.width(), image.height());  // every pixel written by the filter's rows, in parallel
  const float* src[] = {image.data()};
  float* dst[] = {out.data()};
  box_filter(src, dst, 1, g, depth_limit, depth);
  return out;
}

Image<Vec3> depth_aware_box_filter(const Image<Vec3>& image, const GBuffer& g, float depth_limit, const Image<float>* depth) {
  check_size(g, image.width(), image.height());
  // Interleaved RGB lanes directly (3 lanes per pixel, one depth test per lane), no planar copies.
  static_assert(sizeof(Vec3) == 3 * sizeof(float));
  Image<Vec3> out;
  out.resize(image.width(), image.height());
  const float* src[] = {&image.data()->x};
  float* dst[] = {&out.data()->x};
  box_filter(src, dst, 3, g, depth_limit, depth);
  return out;
}

void depth_aware_box_filter_planes(std::span<const float* const> src, std::span<float* const> dst, const GBuffer& g, float depth_limit,
                                   const Image<float>* depth) {
  if (src.size() != dst.size() || src.size() > 4) throw InputError("depth_aware_box_filter_planes: 1 to 4 source planes, one destination each");
  box_filter(src, dst, 1, g, depth_limit, depth);  // up to 4 channels share one pass of depth tests
}

void depth_aware_box_filter_planes(std::span<Image<float>* const> planes, const GBuffer& g, float depth_limit, const Image<float>* depth) {
  for (const Image<float>* p : planes) check_size(g, p->width(), p->height());
  Image<float> own;
  if (!depth && planes.size() > 4) depth = &(own = depth_plane(g));  // built once for every group of 4
  for (std::size_t done = 0; done < planes.size();) {
    const std::size_t k = std::min<std::size_t>(4, planes.size() - done);
    std::array<Image<float>, 4> out;
    std::array<const float*, 4> src{};
    std::array<float*, 4> dst{};
    for (std::size_t c = 0; c < k; ++c) {
      out[c].resize(g.width(), g.height());
      src[c] = planes[done + c]->data(), dst[c] = out[c].data();
    }
    depth_aware_box_filter_planes(std::span(src.data(), k), std::span(dst.data(), k), g, depth_limit, depth);
    for (std::size_t c = 0; c < k; ++c) *planes[done + c] = std::move(out[c]);
    done += k;
  }
}

}  // namespace ao
