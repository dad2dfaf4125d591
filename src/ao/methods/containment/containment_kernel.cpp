// SPDX-License-Identifier: Apache-2.0
// Containment AO's kernel (VAO eq. 5, AT sec. 4 with m tests per ray; screen_space_kernel_internal.h
// states what it computes), compiled once per SIMD target. Lanes are a row's covered pixels; a
// vector of pixels keeps its counts in registers through all of its samples, so the gathers of
// successive test points are independent and several are in flight at once. Multiply-adds are
// written out (MulAdd) in the order the scalar reading of the equation gives; kernels are compiled
// without contraction, so targets with FMA agree bit for bit.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/methods/containment/containment_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "ao/methods/containment/containment_kernel_internal.h"
#include "ao/methods/screen_space_vec_internal.h"
#include "ao/simd/vec_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

using namespace screen_space;  // NOLINT(google-build-using-namespace): the shared per-target vocabulary

template <bool kTwoLayers>
void CountOpenRaysImpl(const CoveredPixels& row, const DepthPlane& plane, const TestPoints& s, int m, float far_limit, float* open) {
  const DF d;
  const Plane pl(plane);
  const StepOffsets offsets(s, m);
  const VF zero = hn::Zero(d), one = hn::Set(d, 1.0f), far = hn::Set(d, far_limit), inf = hn::Set(d, kInfinity);
  for (int k0 = 0; k0 < row.count; k0 += static_cast<int>(hn::Lanes(d))) {
    const Entries e(row, k0);
    const VF minus_bias = hn::Neg(e.bias);
    VF count = zero;
    for (int i = 0; i < s.n; ++i) {
      // AT sec. 4: I = prod_j I0(x + w r j/m), the ray is free only if all m test points are.
      MF blocked = hn::MaskFromVec(zero);
      for (int j = 1; j <= m; ++j) {
        const float* o = offsets.at(i, j);
        VF qx, qy, qz;
        e.point(o[0], o[1], o[2], qx, qy, qz);
        // DepthBufferCharacteristic::distance: z* - depth(p), +infinity behind the camera.
        const VI pixel = pl.pixel(qx, qy, qz);
        const VF zs = hn::GatherIndex(d, pl.depth, pixel);
        const VF dist = hn::IfThenElse(hn::Lt(qz, zero), hn::Add(zs, qz), inf);
        // Occluded: behind the surface by more than the bias, and (AT 4.3) less than R behind it;
        // with a second layer also inside the solid behind the surface (not past its end), and
        // between a closed solid's front and its back face however far behind it (depth_layers.h).
        const MF behind = hn::Lt(dist, minus_bias);
        MF occluded = hn::And(behind, hn::Gt(dist, far));
        if constexpr (kTwoLayers) {
          const VF s2 = gather_where(behind, pl.second, pixel);
          occluded = hn::And(occluded, pl.in_solid(hn::Neg(qz), zs, s2, occluded, pixel, {e.px, e.py, e.pz}, {qx, qy, qz}, e.bias));
          occluded = hn::Or(occluded, hn::And(behind, Plane::inside_closed(hn::Neg(qz), s2)));
        }
        blocked = hn::Or(blocked, occluded);
      }
      count = hn::Add(count, hn::IfThenZeroElse(blocked, one));
    }
    hn::Store(count, d, open + k0);
  }
}

void CountOpenRays(const CoveredPixels& row, const DepthPlane& plane, const TestPoints& s, int m, float far_limit, float* open) {
  if (plane.second)
    CountOpenRaysImpl<true>(row, plane, s, m, far_limit, open);
  else
    CountOpenRaysImpl<false>(row, plane, s, m, far_limit, open);
}

}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ao::simd {

HWY_EXPORT(CountOpenRays);

void count_open_rays(const CoveredPixels& row, const DepthPlane& plane, const TestPoints& samples, int m, float far_limit, float* open) {
  HWY_DYNAMIC_DISPATCH(CountOpenRays)(row, plane, samples, m, far_limit, open);
}

}  // namespace ao::simd
#endif
