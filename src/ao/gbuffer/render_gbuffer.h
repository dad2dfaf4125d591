// Scene -> G-buffer by Embree primary rays, one coherent packet per block of pixels.
#pragma once

#include "ao/core/gbuffer.h"
#include "ao/core/progress.h"
#include "ao/reference/ray_scene.h"

namespace ao {

/// Traces one primary ray through each pixel centre of `camera` (which must validate) and fills
/// every G-buffer channel: camera-space position interpolated on the hit triangle, linear depth,
/// the interpolated shading normal turned to face the camera, the mesh's albedo and id. The
/// optional direct-light pass is left empty (reference/direct_light.h computes one).
GBuffer render_gbuffer(const RayScene& scene, const Camera& camera, const ProgressFn& progress = {});

/// The same into an existing G-buffer, reusing its storage when the size matches (a renderer
/// that draws frame after frame pays for the allocation once). Every pixel is written.
void render_gbuffer(const RayScene& scene, const Camera& camera, GBuffer& out, const ProgressFn& progress = {});

}  // namespace ao
