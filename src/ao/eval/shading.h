// SPDX-License-Identifier: Apache-2.0
// Turning visibility into pictures and pictures into visibility, for people looking at results:
// the display shading of `ao render --shaded` and the lookup of a baked AO map on its mesh
// (`ao render --ao-map`). Neither is an AO method; both are what a viewer does with one.
#pragma once

#include <cstdint>
#include <string>

#include "ao/core/gbuffer.h"
#include "ao/core/image.h"
#include "ao/scene/mesh.h"

namespace ao {

/// The background of pictures for people (--shaded, compare's sheet, ao view) where no surface is
/// visible: a checkerboard of 8-pixel squares of linear grey 0.3 and 0.45, pixel (x, y) from the
/// image's top-left corner. The usual sign of "nothing here" (and what viewers draw under a PNG's
/// transparent pixels); no smooth AO or shaded surface looks like it, whereas white is open surface
/// (V = 1).
inline float display_background(int x, int y) { return ((x >> 3) ^ (y >> 3)) & 1 ? 0.45f : 0.3f; }

/// `v` with display_background where `coverage` (the same size; coverage_mask) is 0: what a picture
/// of V shows, where white is open surface.
Image<float> with_display_background(const Image<float>& v, const Image<std::uint8_t>& coverage);

/// A picture for people, not data: albedo a x V x (ambient + a soft key light) per covered pixel,
/// display_background elsewhere. The key light comes from above-left of the camera (camera space
/// (-0.4, 0.8, 0.45), normalised); wrapping max(0, (n.l + w) / (1 + w)) with w = 0.5 keeps faces
/// turned away from it from going black, so the AO stays readable everywhere; light = 0.45
/// ambient + 0.75 key x wrap.
/// `color`, when not empty, is an RGB result (ambient transfer's W per channel) that replaces V
/// per channel: L = a W La (AT eq. 2) under the same lighting.
/// With a direct-light pass (g.direct not empty) that pass replaces the key light:
/// L = (a V + Ld) La, or (a W + Ld) La (docs/methods/transfer.md), Ld in units of La, La = 0.5
/// display units, so that a white surface in the open (V = 1) facing a sun of E = pi (Ld = 1)
/// shows at 1. Linear values; `visibility` (and `color`) must have the G-buffer's size.
Image<Vec3> shade_for_display(const GBuffer& g, const Image<float>& visibility, const Image<Vec3>& color = {});

/// V from a baked AO map: the map's value at each covered pixel's UV (bilinear, clamped to the
/// edge texels, then to [0, 1]); 1 where the G-buffer is not covered. `g.object_id` - 1 indexes
/// `scene.objects()` (as render_gbuffer writes it; an instance shows its mesh's map). InputError naming `map_name` and the mesh when a
/// visible mesh has no UVs. `map` must not be empty.
Image<float> visibility_from_ao_map(const GBuffer& g, const Scene& scene, const Image<float>& map, const std::string& map_name);

}  // namespace ao
