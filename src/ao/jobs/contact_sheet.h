// The contact sheet of `ao compare` (sheet.png): one row per method, columns [method's V |
// reference's V | signed error heat map]. With a font, a header names the columns and shows the
// heat map's colour scale, and a label above each row names the method and its RMSE.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "ao/core/image.h"
#include "ao/core/math.h"
#include "ao/io/text.h"

namespace ao {

/// One row of the sheet. The three images have the same size, and every row the same size.
struct SheetRow {
  const Image<float>* method = nullptr;     ///< The method's V; drawn as linear grey.
  const Image<float>* reference = nullptr;  ///< Its ray-traced reference's V.
  const Image<Vec3>* heat = nullptr;        ///< signed_error_heat_map(method, reference) with heat_range.
  /// Pieces of the row's label ("alchemy", "samples=12", "RMSE 0.1947"), drawn on one line when
  /// they fit and otherwise wrapped between pieces, never inside one.
  std::vector<std::string> label;
  /// Optional, the images' size: 0 where no surface is visible, drawn as display_background
  /// (eval/shading.h) in all three images so that it is not mistaken for open surface.
  const Image<std::uint8_t>* coverage = nullptr;
};

/// Lays `rows` (at least one) out on a dark background with 4-pixel gutters. With `font`: a header
/// with the column titles and the heat map's colour scale from -heat_range to +heat_range, and each
/// row's label above its images; text is 1/20 of the image width high, at least 12 and at most 32
/// pixels, and a column is widened beyond the image width when its title or the scale needs it.
/// Without a font: the images only, in a 3 x rows grid.
Image<Vec3> contact_sheet(std::span<const SheetRow> rows, float heat_range, const Font* font);

}  // namespace ao
