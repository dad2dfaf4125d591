// SPDX-License-Identifier: Apache-2.0
// Ray-traced reference of volumetric AO (Szirmay-Kalos et al., "Volumetric Ambient Occlusion for
// Real-Time Rendering and Games", VAO): the fraction of the tangent sphere S (radius R/2, centre
// x + N R/2, eq. 6-7) that is visible from x, which is the quantity the method's V estimates.
//
// Derivation (docs/methods/volumetric.md#reference): a point of S in direction w at distance r from
// x is free of occluders between x and itself when r < D(w), D the distance to the first surface.
// S seen from x is r < R cos(theta), and a volume element is r^2 dr dw, so
//
//   V(x) = (1/|S|) * integral over S of eps(D(w) - r) dp
//        = (2/pi) * integral over the hemisphere of min(D(w)/R, cos theta)^3 dw,    |S| = pi R^3 / 6.
//
// Monte Carlo with directions of pdf 2 cos^3(theta) / pi (the integrand's bound; it integrates to 1
// over the hemisphere) leaves the plain mean of min(D / (R cos theta), 1)^3 over the samples: the
// free fraction of each sampled chord, cubed. A ray needs to look only R cos(theta) far, and an
// open point gives exactly 1. VAO's screen-space estimator replaces eps(D - r) by its
// characteristic function I(p) (eq. 5's containment test), equal to it while a ray crosses the
// surface at most once within the sphere.
#pragma once

#include <cstdint>

#include "ao/core/gbuffer.h"
#include "ao/core/progress.h"
#include "ao/reference/ray_scene.h"
#include "ao/reference/raytraced.h"

namespace ao {

/// The visible fraction of the tangent sphere of radius `radius` / 2 at world point p with unit
/// normal n; `radius` = R > 0, world units. `params` as for estimate_visibility (samples, adaptive
/// stopping, ray offset); `seed` keys the point's scrambled sample set.
VisibilityEstimate estimate_tangent_sphere(const RayScene& scene, Vec3 p, Vec3 n, float radius, const RaytracedParams& params,
                                           std::uint32_t seed);

/// The same for every covered pixel of `gbuffer` (whose camera carries its world placement), with
/// the sample set of pixel (x, y) keyed by pixel_seed(seed, x, y): independent of the thread count.
/// V = 1 and standard error 0 where not covered.
RaytracedImage render_tangent_sphere(const RayScene& scene, const GBuffer& gbuffer, float radius, const RaytracedParams& params,
                                     std::uint32_t seed, const ProgressFn& progress = {});

}  // namespace ao
