// SPDX-License-Identifier: Apache-2.0
// Volumetric AO's kernel: the free lengths of the tangent sphere's pipes (VAO eq. 6-7, fig. 4 and
// 7; screen_space_kernel_internal.h states what it computes), compiled once per SIMD target. Lanes
// are a row's covered pixels; multiply-adds are written out (MulAdd) in the order the scalar reading
// of the equations gives, compiled without contraction, so targets with FMA agree bit for bit.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ao/methods/volumetric/volumetric_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "ao/methods/volumetric/volumetric_kernel_internal.h"
#include "ao/methods/screen_space_vec_internal.h"
#include "ao/simd/vec_internal.h"

HWY_BEFORE_NAMESPACE();
namespace ao::simd::HWY_NAMESPACE {

using namespace screen_space;  // NOLINT(google-build-using-namespace): the shared per-target vocabulary

template <bool kTwoLayers>
void SumFreePipesImpl(const CoveredPixels& row, const DepthPlane& plane, float half_radius, const TestPoints& disk, float far_limit,
                      float* free) {
  const DF d;
  const Plane pl(plane);
  const VF zero = hn::Zero(d), hr = hn::Set(d, half_radius), lim = hn::Set(d, far_limit), inf = hn::Set(d, kInfinity);
  const VF minus_huge = hn::Set(d, -1e30f);  // below this a distance stands for -infinity (never distant)
  for (int k0 = 0; k0 < row.count; k0 += static_cast<int>(hn::Lanes(d))) {
    // Fig. 4: the tangent sphere's centre c = x + N R/2. Its pipes run along the view axis at depth
    // c_z, so the divide by -c_z and the pixel's rotation fold into affine coefficients of the
    // disk sample (x_i, y_i):  f_x = f_x0 + x_i a_x - y_i b_x,  f_y = f_y0 - x_i a_y - y_i b_y.
    const VF cx = hn::MulAdd(hr, hn::Load(d, row.nx.data() + k0), hn::Load(d, row.px.data() + k0));
    const VF cy = hn::MulAdd(hr, hn::Load(d, row.ny.data() + k0), hn::Load(d, row.py.data() + k0));
    const VF cz = hn::MulAdd(hr, hn::Load(d, row.nz.data() + k0), hn::Load(d, row.pz.data() + k0));
    const VF rc = hn::Load(d, row.rc.data() + k0), rs = hn::Load(d, row.rs.data() + k0), bias = hn::Load(d, row.bias.data() + k0);
    const Point3 x{hn::Load(d, row.px.data() + k0), hn::Load(d, row.py.data() + k0), hn::Load(d, row.pz.data() + k0)};
    const VF inv = hn::Div(hn::Set(d, -1.0f), cz), kx = hn::Mul(inv, pl.scale_x), ky = hn::Mul(inv, pl.scale_y);
    const VF fx0 = hn::MulAdd(cx, kx, pl.centre_x), fy0 = hn::NegMulAdd(cy, ky, pl.centre_y);
    const VF ax = hn::Mul(rc, kx), bx = hn::Mul(rs, kx), ay = hn::Mul(rs, ky), by = hn::Mul(rc, ky);
    // As ScreenProjection::locate: clamp-to-edge, free only behind the camera.
    const MF valid = hn::Lt(cz, zero);
    VF acc = zero;
    for (int i = 0; i < disk.n; ++i) {
      const float xi = half_radius * disk.x[i], yi = half_radius * disk.y[i];
      const float half_chord = half_radius * disk.z[i];  // (R/2) h_i = z_c - z_entry
      const VF hc = hn::Set(d, half_chord), chord = hn::Set(d, 2.0f * half_chord);  // z_exit - z_entry
      const VF vxi = hn::Set(d, xi), vyi = hn::Set(d, yi);
      const VF fx = hn::NegMulAdd(vyi, bx, hn::MulAdd(vxi, ax, fx0)), fy = hn::NegMulAdd(vyi, by, hn::NegMulAdd(vxi, ay, fy0));
      // Clamp-to-edge as Plane::pixel (behind the camera the pixel is any one: the pipe is free).
      const VI ix = truncate_in_range(hn::Min(hn::Max(fx, zero), pl.max_x));
      const VI iy = truncate_in_range(hn::Min(hn::Max(fy, zero), pl.max_y));
      const VI pixel = hn::Add(hn::Mul(iy, pl.width), ix);
      const VF zs = hn::GatherIndex(d, pl.depth, pixel);
      // DepthBufferCharacteristic::distance z* - z_c, then z* - z_entry = (z* - z_c) + (R/2) h_i.
      const VF to_surface = hn::Add(hn::Add(hn::IfThenElse(valid, hn::Add(zs, cz), inf), hc), bias);
      // Fig. 7: dz = clamp(z* - z_entry, 0, chord): (a) surface inside: z* - z_entry; (b) behind:
      // the chord; (c) in front: 0. A distant foreground surface (AT 4.3) leaves the pipe free.
      VF dz = hn::Min(hn::Max(to_surface, zero), chord);
      VF distant_free = chord;  // a distant foreground surface's pipe: free (AT 4.3)
      if constexpr (kTwoLayers) {
        // The solid in the pipe is [dz, end) and [next, chord) from its entry (depth_layers.h), so
        // the free length is next - max(0, end - dz), both clamped to the pipe.
        const MF reaches = hn::And(valid, hn::Lt(to_surface, chord));  // the solid begins inside the pipe
        const VF s2 = gather_where(reaches, pl.second, pixel);
        const VF from_entry = hn::Add(cz, hc);  // depth z - z_entry = z + c_z + (R/2) h_i
        VF end = hn::Min(hn::Max(hn::Add(pl.solid_end(zs, s2), from_entry), zero), chord);
        const VF next = hn::Min(hn::Max(hn::Add(Plane::next_solid(s2), from_entry), zero), chord);
        // Before a closed solid's exit the pipe is solid whatever AT 4.3 says (depth_layers.h).
        const VF leaves = hn::Min(hn::Max(hn::Add(s2, from_entry), zero), chord);
        distant_free = hn::IfThenElse(hn::And(reaches, Plane::closed_exit(s2)), hn::Sub(chord, hn::Max(hn::Sub(leaves, dz), zero)), chord);
        // Behind a sheet the gap [end, next) is solid where the sheet hides it from x, judged at
        // the gap's middle: the pipe's point (c_x + x_i cos - y_i sin, c_y + x_i sin + y_i cos) at
        // depth z_entry + (end + next) / 2.
        const MF gap = hn::AndNot(Plane::back_face(s2), hn::And(reaches, hn::Lt(end, next)));
        if (!hn::AllFalse(d, gap)) {
          const Point3 mid{hn::NegMulAdd(vyi, rs, hn::MulAdd(vxi, rc, cx)), hn::MulAdd(vyi, rc, hn::MulAdd(vxi, rs, cy)),
                           hn::NegMulAdd(hn::Add(end, next), hn::Set(d, 0.5f), hn::Add(cz, hc))};
          const Point3 on_sheet{mid.x, mid.y, hn::Neg(zs)};  // the pipe runs along the view axis
          end = hn::IfThenElse(pl.sheet_hides(gap, pixel, on_sheet, x, mid, bias), next, end);
        }
        dz = hn::IfThenElse(reaches, hn::Sub(next, hn::Max(hn::Sub(end, dz), zero)), dz);
      }
      const MF distant = hn::And(hn::Lt(to_surface, lim), hn::Gt(to_surface, minus_huge));
      acc = hn::Add(acc, hn::IfThenElse(distant, distant_free, dz));
    }
    hn::Store(acc, d, free + k0);
  }
}

void SumFreePipes(const CoveredPixels& row, const DepthPlane& plane, float half_radius, const TestPoints& disk, float far_limit, float* free) {
  if (plane.second)
    SumFreePipesImpl<true>(row, plane, half_radius, disk, far_limit, free);
  else
    SumFreePipesImpl<false>(row, plane, half_radius, disk, far_limit, free);
}

}  // namespace ao::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ao::simd {

HWY_EXPORT(SumFreePipes);

void sum_free_pipes(const CoveredPixels& row, const DepthPlane& plane, float half_radius, const TestPoints& disk, float far_limit,
                    float* free) {
  HWY_DYNAMIC_DISPATCH(SumFreePipes)(row, plane, half_radius, disk, far_limit, free);
}

}  // namespace ao::simd
#endif
