// SPDX-License-Identifier: Apache-2.0
// The contact sheet of `ao compare` (sheet.png): one row per method, a column per image: [method's
// V | reference's V | signed error heat map], and with the GPU backend the method's V and its heat
// map once per backend. With a font, a header names the columns and shows the heat map's colour
// scale, and a label above each row names the method and its RMSE.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "ao/core/image.h"
#include "ao/core/math.h"
#include "ao/io/text.h"

namespace ao {

/// One column of the sheet.
struct SheetColumn {
  /// Pieces of its title ("ray-traced", "reference"), wrapped between pieces, never inside one.
  std::vector<std::string> title;
  /// Its cells are signed-error heat maps: the header shows their colour scale under the title.
  bool heat = false;
};

/// One image of a row: grey (V, drawn as linear grey) or RGB (a heat map); neither: left empty.
struct SheetCell {
  const Image<float>* grey = nullptr;
  const Image<Vec3>* rgb = nullptr;
};

/// One row of the sheet: a cell per column. Every image of the sheet has the same size.
struct SheetRow {
  std::vector<SheetCell> cells;
  /// Pieces of the row's label ("alchemy", "samples=12", "RMSE 0.1947"), drawn on one line when
  /// they fit and otherwise wrapped between pieces, never inside one.
  std::vector<std::string> label;
  /// Optional, the images' size: 0 where no surface is visible, drawn as display_background
  /// (eval/shading.h) in all three images so that it is not mistaken for open surface.
  const Image<std::uint8_t>* coverage = nullptr;
};

/// Lays `rows` (at least one, with at least one image) out under `columns` on a dark background
/// with 4-pixel gutters. With `font`: a header with the column titles and, under each heat
/// column's title, the heat map's colour scale from -heat_range to +heat_range, and each row's
/// label above its images; text is 1/20 of the image width high, at least 12 and at most 32
/// pixels, and every column is widened beyond the image width when a title or the scale needs it.
/// Without a font: the images only, in a columns x rows grid.
Image<Vec3> contact_sheet(std::span<const SheetColumn> columns, std::span<const SheetRow> rows, float heat_range, const Font* font);

}  // namespace ao
