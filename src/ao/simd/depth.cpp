// Kernel of the depth plane (depth_internal.h), compiled once per SIMD target: the positions' z
// deinterleaved from their 12-byte records a vector at a time, the background replaced by +infinity.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/simd/depth.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "ao/simd/depth_internal.h"
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
#endif
