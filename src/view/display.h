// SPDX-License-Identifier: Apache-2.0
// The image `ao view` shows, as 8-bit codes: the method's V (or the shaded picture, transfer's W,
// the baked map, the error heat map) left of the wipe and the reference right of it. Plain CPU
// work; the window uploads the bytes.
#pragma once

#include <cstdint>
#include <vector>

#include "ao/core/gbuffer.h"
#include "ao/core/image.h"
#include "view/state.h"

namespace ao::view {

/// |signed error| at full colour, as ao compare's sheets.
inline constexpr float kHeatRange = 0.25f;

/// What one displayed image is made of. Empty images are absent.
struct DisplayInputs {
  const GBuffer* gbuffer = nullptr;
  ViewMode view = ViewMode::AO;
  const Image<float>* method = nullptr;     ///< The method's V (the reference's, for the ground truth).
  const Image<float>* reference = nullptr;  ///< The progressive reference's V; may be empty.
  const Image<Vec3>* color = nullptr;       ///< Transfer's W per channel; may be empty.
  const Image<Vec3>* shaded = nullptr;      ///< shade_for_display, linear; may be empty.
  const Image<float>* map = nullptr;        ///< V from the baked AO map; may be empty.
  float wipe = 1.0f;
};

/// Whether `view` is shown in grey (one byte per pixel) rather than RGBA8.
bool grey_view(ViewMode view);

/// The bytes of columns [x0, width) of the image (rows in parallel), into `pixels` (resized to
/// width x height x 1 or 4). A linear V of c becomes the byte lround(255 c) of the clamped value,
/// as the PNG writer quantises, so a screenshot of the AO view holds the bytes of `ao render -o x.png`
/// where a surface is visible; elsewhere every view shows display_background (eval/shading.h), where
/// that PNG is transparent.
void build_display(std::vector<std::uint8_t>& pixels, const DisplayInputs& in, int x0);

}  // namespace ao::view
