// SPDX-License-Identifier: Apache-2.0
// Kernel of the depth plane (depth_plane.h, depth_internal.h), compiled once per SIMD target: the
// positions' z deinterleaved from their 12-byte records a vector at a time, the background replaced
// by +infinity.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/simd/depth_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "ao/core/parallel.h"
#include "ao/simd/depth_internal.h"
#include "ao/simd/depth_plane.h"
#include "ao/simd/vec_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

void DepthPlaneTile(const Vec3* position, const std::uint32_t* object_id, int width, int x0, int x1, int y0, int y1, float* out) {
  const DF d;
  const DU du;
  const int lanes = static_cast<int>(hn::Lanes(d));
  const VF inf = hn::Set(d, kInfinity);
  for (int y = y0; y < y1; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * width;
    int x = x0;
    for (; x + lanes <= x1; x += lanes) {
      VF px, py, pz;
      hn::LoadInterleaved3(d, &position[row + x].x, px, py, pz);
      const auto covered = hn::RebindMask(d, hn::Not(hn::Eq(hn::LoadU(du, object_id + row + x), hn::Zero(du))));
      hn::StoreU(hn::IfThenElse(covered, hn::Neg(pz), inf), d, out + row + x);
    }
    for (; x < x1; ++x) out[row + x] = object_id[row + x] != 0 ? -position[row + x].z : kInfinity;
  }
}

}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ao::simd {

HWY_EXPORT(DepthPlaneTile);

void depth_plane_tile(const Vec3* position, const std::uint32_t* object_id, int width, int x0, int x1, int y0, int y1, float* out) {
  HWY_DYNAMIC_DISPATCH(DepthPlaneTile)(position, object_id, width, x0, x1, y0, y1, out);
}

}  // namespace ao::simd

namespace ao {

void depth_plane(const GBuffer& g, Image<float>& out) {
  const int w = g.width(), h = g.height();
  out.resize(w, h);
  // Rows of 64 x 16 pixels: each task streams 768 bytes of positions and 256 of ids per row.
  parallel_for_tiles(w, h, 64, 16, [&](const Tile& t) {
    simd::depth_plane_tile(g.position.data(), g.object_id.data(), w, t.x0, t.x1, t.y0, t.y1, out.data());
  });
}

Image<float> depth_plane(const GBuffer& g) {
  Image<float> out;
  depth_plane(g, out);
  return out;
}

}  // namespace ao
#endif
