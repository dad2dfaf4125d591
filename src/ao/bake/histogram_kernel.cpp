// SPDX-License-Identifier: Apache-2.0
// Kernels of the outside-in baker's stages 1 and 2 (histogram_internal.h; bake/histogram.cpp for
// the method), compiled once per SIMD target. Stage 1 is a half-space rasteriser tuned for what
// baking feeds it: many small triangles (an 89k-triangle mesh at map resolution covers a few pixels
// each), one orthographic view per direction. Each triangle is set up once (bounding box, three
// edge functions, a depth plane), then its box is scanned with incremental edge functions; the
// per-direction images are a few hundred thousand pixels, which fit in L2 with the projected
// vertices.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/bake/histogram_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <algorithm>
#include <cmath>

#include <hwy/highway.h>

#include "ao/bake/histogram_kernel_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

void RasterizeFrontFaces(const RasterInput& in, float* px, float* py, float* pz, float* depth, std::uint32_t* ids) {
  const float inv = 1.0f / in.pixel_size;
  const Frame& f = in.frame;
  for (std::size_t i = 0; i < in.vertices; ++i) {
    const Vec3 p = in.positions[i] - in.origin;
    px[i] = dot(p, f.t) * inv;
    py[i] = dot(p, f.b) * inv;
    pz[i] = dot(in.positions[i], f.n);
  }
  const int w = in.width, h = in.height;
  std::fill(depth, depth + static_cast<std::size_t>(w) * h, -kInfinity);
  std::fill(ids, ids + static_cast<std::size_t>(w) * h, 0u);
  for (std::size_t t = 0; t < in.triangles; ++t) {
    const std::uint32_t i0 = in.indices[3 * t], i1 = in.indices[3 * t + 1], i2 = in.indices[3 * t + 2];
    const float ax = px[i0], ay = py[i0], bx = px[i1], by = py[i1], cx = px[i2], cy = py[i2];
    // Twice the signed image area; (t, b, w) is right-handed, so a counter-clockwise front face
    // seen from the light has area > 0. Back faces and edge-on faces are culled.
    const float area2 = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay);
    if (!(area2 > 0)) continue;
    // Pixel centres (i + 0.5) inside the bounding box.
    const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({ax, bx, cx}) - 0.5f)));
    const int x1 = std::min(w - 1, static_cast<int>(std::floor(std::max({ax, bx, cx}) - 0.5f)));
    const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({ay, by, cy}) - 0.5f)));
    const int y1 = std::min(h - 1, static_cast<int>(std::floor(std::max({ay, by, cy}) - 0.5f)));
    if (x0 > x1 || y0 > y1) continue;
    // Edge functions E(p) = (q1 - q0) x (p - q0), positive inside. Tie rule for centres exactly on
    // an edge: keep them for edges whose direction is "positive" (dy > 0, or dy = 0 and dx > 0).
    // The two triangles sharing an edge traverse it in opposite directions, so exactly one keeps them.
    struct Edge {
      float a, b, c;  // E = a x + b y + c
      bool keep_zero;
    };
    auto edge = [](float qx0, float qy0, float qx1, float qy1) {
      const float dx = qx1 - qx0, dy = qy1 - qy0;
      return Edge{-dy, dx, dy * qx0 - dx * qy0, dy > 0 || (dy == 0 && dx > 0)};
    };
    const Edge e0 = edge(bx, by, cx, cy);  // opposite a: barycentric of a
    const Edge e1 = edge(cx, cy, ax, ay);  // opposite b
    const Edge e2 = edge(ax, ay, bx, by);  // opposite c
    const float inv_area = 1.0f / area2;
    const float za = pz[i0], zb = pz[i1], zc = pz[i2];
    // Depth plane z = za + l1 (zb - za) + l2 (zc - za), with l1 = E1 / area2, l2 = E2 / area2.
    const float dz1 = (zb - za) * inv_area, dz2 = (zc - za) * inv_area;
    const float zx = e1.a * dz1 + e2.a * dz2, zy = e1.b * dz1 + e2.b * dz2, zc0 = za + e1.c * dz1 + e2.c * dz2;
    const auto tri_id = static_cast<std::uint32_t>(t + 1);
    for (int y = y0; y <= y1; ++y) {
      const float fy = static_cast<float>(y) + 0.5f;
      const float fx0 = static_cast<float>(x0) + 0.5f;
      float w0 = e0.a * fx0 + e0.b * fy + e0.c;
      float w1 = e1.a * fx0 + e1.b * fy + e1.c;
      float w2 = e2.a * fx0 + e2.b * fy + e2.c;
      float z = zx * fx0 + zy * fy + zc0;
      const std::size_t row = static_cast<std::size_t>(y) * w;
      for (int x = x0; x <= x1; ++x) {
        const bool inside = (w0 > 0 || (w0 == 0 && e0.keep_zero)) && (w1 > 0 || (w1 == 0 && e1.keep_zero)) && (w2 > 0 || (w2 == 0 && e2.keep_zero));
        if (inside && z > depth[row + x]) {
          depth[row + x] = z;
          ids[row + x] = tri_id;
        }
        w0 += e0.a;
        w1 += e1.a;
        w2 += e2.a;
        z += zx;
      }
    }
  }
}

std::uint64_t ScatterHistogram(const ScatterInput& in, std::uint64_t* sum, std::int64_t* bent) {
  std::uint64_t fragments = 0;
  const float* px = in.px;
  const float* py = in.py;
  const float* cos_v = in.cos_v;
  for (int y = 0; y < in.view_height; ++y) {
    const float fy = static_cast<float>(y) + 0.5f;
    for (int x = 0; x < in.view_width; ++x) {
      const std::uint32_t id = in.ids[static_cast<std::size_t>(y) * in.view_width + x];
      if (id == 0) continue;  // background: V = 0 (sec. 3)
      const std::size_t t = id - 1;
      if (!in.has_uv[t]) continue;
      const std::uint32_t i0 = in.indices[3 * t], i1 = in.indices[3 * t + 1], i2 = in.indices[3 * t + 2];
      const float fx = static_cast<float>(x) + 0.5f;
      const float ax = px[i0], ay = py[i0];
      const float area2 = (px[i1] - ax) * (py[i2] - ay) - (px[i2] - ax) * (py[i1] - ay);
      const float l1 = ((ax - px[i2]) * (fy - py[i2]) - (ay - py[i2]) * (fx - px[i2])) / area2;
      const float l2 = ((px[i1] - ax) * (fy - ay) - (py[i1] - ay) * (fx - ax)) / area2;
      const Vec2 ua = in.uvs[i0], ub = in.uvs[i1], uc = in.uvs[i2];
      const float u = ua.x + l1 * (ub.x - ua.x) + l2 * (uc.x - ua.x);
      const float v = ua.y + l1 * (ub.y - ua.y) + l2 * (uc.y - ua.y);
      const int tx = static_cast<int>(std::floor(u)), ty = static_cast<int>(std::floor(v));
      if (tx < 0 || ty < 0 || tx >= in.map_width || ty >= in.map_height) continue;
      // (w . n) with the interpolated normal, as the paper's fragment program computes it;
      // directions below the shading normal's horizon contribute nothing.
      const float cos_s = std::max(0.0f, cos_v[i0] + l1 * (cos_v[i1] - cos_v[i0]) + l2 * (cos_v[i2] - cos_v[i0]));
      // |J| (eq. 9) in texels^2 per pixel: UV area over image area, both of this triangle.
      const float uv_area2 = std::abs((ub.x - ua.x) * (uc.y - ua.y) - (uc.x - ua.x) * (ub.y - ua.y));
      const float jac = uv_area2 / area2;
      // Area: times s / p^2 (surface per texel^2, in pixels): weight = (w . n)/(w . n_g), 1 on flat
      // geometry. Max: the paper's (w . n)|J|.
      float weight = cos_s * jac * (in.area_norm ? in.stretch[t] / (in.pixel_size * in.pixel_size) : 1.0f);
      weight = std::min(weight, in.max_weight);
      const auto q = static_cast<std::uint64_t>(static_cast<double>(weight) * in.fixed_scale + 0.5);
      const std::size_t texel = static_cast<std::size_t>(ty) * in.map_width + tx;
      sum[texel] += q;
      ++fragments;
      if (in.bent) {
        const auto sq = static_cast<std::int64_t>(q >> 10);
        bent[3 * texel] += sq * in.bx;
        bent[3 * texel + 1] += sq * in.by;
        bent[3 * texel + 2] += sq * in.bz;
      }
    }
  }
  return fragments;
}

}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ao::simd {

HWY_EXPORT(RasterizeFrontFaces);
HWY_EXPORT(ScatterHistogram);

void rasterize_front_faces(const RasterInput& in, float* px, float* py, float* pz, float* depth, std::uint32_t* ids) {
  HWY_DYNAMIC_DISPATCH(RasterizeFrontFaces)(in, px, py, pz, depth, ids);
}

std::uint64_t scatter_histogram(const ScatterInput& in, std::uint64_t* sum, std::int64_t* bent) {
  return HWY_DYNAMIC_DISPATCH(ScatterHistogram)(in, sum, bent);
}

}  // namespace ao::simd
#endif
