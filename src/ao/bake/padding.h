// SPDX-License-Identifier: Apache-2.0
// UV padding (a margin around every chart) and the paper's seam fix (McGraw & Sowers, sec. 3.3:
// erosion, then two dilations). Both are "copy the nearest valid texel outwards".
#pragma once

#include <cstdint>

#include "ao/core/image.h"
#include "ao/core/math.h"

namespace ao {

/// Default margin in texels: 16, Blender's default bake margin. It keeps mip level 4 (1/16 of the
/// resolution) free of background, which is as deep as engines sample a 1024 map on screen at
/// normal viewing distances; it costs nothing in the charts themselves.
inline constexpr int kDefaultPadding = 16;

/// For every texel within `margin` texels (8-connected rings) of a valid one, the index of the
/// nearest valid texel (Euclidean distance among the candidates propagated ring by ring); -1 for
/// texels farther away; a valid texel maps to itself. margin >= 0; at most 65536 x 32768 texels.
Image<std::int32_t> nearest_valid_texel(const Image<std::uint8_t>& valid, int margin);

/// Copies each texel's nearest valid texel into it (padding); texels beyond the margin keep their value.
void pad(Image<float>& image, const Image<std::int32_t>& nearest);
void pad(Image<Vec3>& image, const Image<std::int32_t>& nearest);

/// Morphological erosion of a mask with the 4-neighbourhood: a texel stays only if it and its four
/// neighbours are set (the paper's step that discards chart-boundary texels).
Image<std::uint8_t> erode(const Image<std::uint8_t>& mask);

}  // namespace ao
