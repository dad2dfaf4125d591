// SPDX-License-Identifier: Apache-2.0
// Scene -> G-buffer by Embree primary rays, one coherent packet per block of pixels.
#pragma once

#include "ao/core/gbuffer.h"
#include "ao/core/progress.h"
#include "ao/reference/ray_scene.h"

namespace ao {

/// Traces one primary ray through each pixel centre of `camera` (which must validate) and fills
/// the G-buffer: camera-space position interpolated on the hit triangle (linear depth and coverage
/// follow from it and the id: GBuffer::depth, ::covered), the normal
/// chosen by `options` turned to face the camera (the shading normal onto the side of the
/// geometric one), the mesh's id, the triangle's index (primitive_id), and the mesh's albedo and
/// the UVs unless `options` leave them out (then those images are empty). The optional
/// direct-light pass is left empty (reference/direct_light.h computes one). The images are
/// written with non-temporal stores: they are not left in the cache.
GBuffer render_gbuffer(const RayScene& scene, const Camera& camera, const GBufferOptions& options, const ProgressFn& progress = {});
/// The same with default options.
GBuffer render_gbuffer(const RayScene& scene, const Camera& camera, const ProgressFn& progress = {});

/// The same into an existing G-buffer, reusing its storage when the size matches (a renderer
/// that draws frame after frame pays for the allocation once). Every pixel is written.
void render_gbuffer(const RayScene& scene, const Camera& camera, const GBufferOptions& options, GBuffer& out,
                    const ProgressFn& progress = {});
/// The same with default options.
void render_gbuffer(const RayScene& scene, const Camera& camera, GBuffer& out, const ProgressFn& progress = {});

/// The deep G-buffer's second layer (Mara et al. 2016, "Deep G-Buffers for Stable Global
/// Illumination Approximation"): along each covered pixel's primary ray, the nearest surface at
/// least `separation` (world units, > 0: the paper's minimum separation Delta) behind the visible
/// one, by one more Embree ray from depth + separation. Written into g.second_depth (see GBuffer for
/// its signed encoding) and g.second_separation; `g` must come from render_gbuffer of `scene`
/// (its camera carries the world placement). InputError for a separation that is not finite and > 0.
void render_second_layer(const RayScene& scene, GBuffer& g, float separation, const ProgressFn& progress = {});
/// The same layer as a new image, leaving `g` as it is (a method that needs the layer of a
/// G-buffer it may only read).
Image<float> render_second_layer_depth(const RayScene& scene, const GBuffer& g, float separation, const ProgressFn& progress = {});

}  // namespace ao
