// SPDX-License-Identifier: Apache-2.0
// The contact sheet is built as horizontal bands (the header, then one per row: label above
// images) that are stacked with gutters between them.
#include "ao/jobs/contact_sheet.h"

#include <algorithm>
#include <cstdio>

#include "ao/core/error.h"
#include "ao/eval/metrics.h"
#include "ao/eval/shading.h"

namespace ao {

namespace {

constexpr int kGap = 4;  // gutter between images and around the sheet, pixels
constexpr Vec3 kBackground{0.1f, 0.1f, 0.1f};
constexpr Vec3 kTitleColour{0.75f, 0.75f, 0.75f};  // the header is quieter than the row labels
constexpr Vec3 kLabelColour{1.0f, 1.0f, 1.0f};
constexpr const char* kLabelJoiner = "   ";

// Text height: 1/20 of the image width, so the text keeps its proportion to the images when a page
// shrinks the sheet (32 pixels at the docs' 640-pixel cells are still 15 on a sheet shown at half
// size), and at least 12 pixels, below which DejaVu Sans stops being comfortable to read.
int text_pixels(int image_width) { return std::clamp(image_width / 20, 12, 32); }

// Greedy line breaking: as many units per line as fit in `width`, joined by `joiner`. A unit wider
// than `width` gets a line of its own (and draw_text clips it at the edge of the band).
std::vector<std::string> wrap(const Font& font, int px, const std::vector<std::string>& units, const std::string& joiner, int width) {
  std::vector<std::string> lines;
  std::string line;
  for (const std::string& unit : units) {
    const std::string longer = line.empty() ? unit : line + joiner + unit;
    if (line.empty() || text_width(font, longer, px) <= width) {
      line = longer;
    } else {
      lines.push_back(line);
      line = unit;
    }
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

void paste(Image<Vec3>& dst, int ox, int oy, const Image<Vec3>& src) {
  for (int y = 0; y < src.height(); ++y)
    for (int x = 0; x < src.width(); ++x) dst(ox + x, oy + y) = src(x, y);
}

void paste(Image<Vec3>& dst, int ox, int oy, const Image<float>& grey) {
  for (int y = 0; y < grey.height(); ++y)
    for (int x = 0; x < grey.width(); ++x) dst(ox + x, oy + y) = Vec3{grey(x, y), grey(x, y), grey(x, y)};
}

// Over a pasted image at (ox, oy): display_background where `coverage` is 0, the checkerboard
// counted from the image's own corner.
void mark_background(Image<Vec3>& dst, int ox, int oy, const Image<std::uint8_t>& coverage) {
  for (int y = 0; y < coverage.height(); ++y)
    for (int x = 0; x < coverage.width(); ++x)
      if (coverage(x, y) == 0) {
        const float b = display_background(x, y);
        dst(ox + x, oy + y) = {b, b, b};
      }
}

// "+0.25", "-0.25": shortest form, sign always shown.
std::string with_sign(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%+g", v);
  return buf;
}

// Width of a sheet of `columns` columns of width `col_w`, with the gutters.
int sheet_width(std::size_t columns, int col_w) { return static_cast<int>(columns) * (col_w + kGap) + kGap; }
int column_x(int c, int col_w) { return kGap + c * (col_w + kGap); }

// What the header and labels share.
struct Layout {
  const Font& font;
  int px;      // text height, pixels (the font's em size)
  int line;    // line height
  int pad;     // space above a block of text
  int col_w;   // width of a column: the image's, or more when a title word or the scale needs it
  int sheet_w;
  int column_x(int c) const { return ao::column_x(c, col_w); }
};

// The heat map's scale: the numbers at its ends and middle, and the narrowest bar they fit under.
struct Scale {
  std::string low, mid, high;
  int min_width = 0;
};

Scale scale_of(const Font& font, int px, float heat_range) {
  Scale s{with_sign(-heat_range), "0", with_sign(heat_range)};
  s.min_width = text_width(font, s.low, px) + text_width(font, s.mid, px) + text_width(font, s.high, px) + 2 * px;
  return s;
}

// The colour scale of the heat maps at (x, y): a bar from -range (blue) through 0 (white) to +range
// (red), coloured by the heat map's own function, with the three numbers below.
void draw_scale(Image<Vec3>& band, const Layout& l, const Scale& scale, int x, int y, int bar_w, float heat_range) {
  const int bar_h = std::max(6, l.px * 2 / 3);
  for (int i = 0; i < bar_w; ++i) {
    const float error = heat_range * (2.0f * (static_cast<float>(i) + 0.5f) / static_cast<float>(bar_w) - 1.0f);
    for (int j = 0; j < bar_h; ++j) band(x + i, y + j) = signed_error_colour(error, heat_range);
  }
  const int number_y = y + bar_h + 2;
  draw_text(l.font, band, x, number_y, scale.low, l.px, kTitleColour);
  draw_text(l.font, band, x + (bar_w - text_width(l.font, scale.mid, l.px)) / 2, number_y, scale.mid, l.px, kTitleColour);
  draw_text(l.font, band, x + bar_w - text_width(l.font, scale.high, l.px), number_y, scale.high, l.px, kTitleColour);
}

// Column titles, and under each heat column's title the colour scale.
Image<Vec3> header_band(const Layout& l, std::span<const SheetColumn> columns, const Scale& scale, int image_width, float heat_range) {
  std::vector<std::vector<std::string>> titles;
  std::size_t title_lines = 0;
  for (const SheetColumn& c : columns) {
    titles.push_back(wrap(l.font, l.px, c.title, " ", l.col_w));
    title_lines = std::max(title_lines, titles.back().size());
  }
  const int bar_y = l.pad + static_cast<int>(title_lines) * l.line + l.pad / 2;
  const int bar_h = std::max(6, l.px * 2 / 3);
  const int bar_w = std::max(scale.min_width, std::min(image_width, 10 * l.px));  // <= col_w, which is >= both
  Image<Vec3> band(l.sheet_w, bar_y + bar_h + 2 + l.line, kBackground);
  for (std::size_t c = 0; c < columns.size(); ++c) {
    const int x = l.column_x(static_cast<int>(c));
    for (std::size_t i = 0; i < titles[c].size(); ++i) draw_text(l.font, band, x, l.pad + static_cast<int>(i) * l.line, titles[c][i], l.px, kTitleColour);
    if (columns[c].heat) draw_scale(band, l, scale, x, bar_y, bar_w, heat_range);
  }
  return band;
}

// The size of the sheet's images: the first image of the first row that has one.
std::pair<int, int> image_size(std::span<const SheetRow> rows) {
  for (const SheetRow& row : rows)
    for (const SheetCell& c : row.cells) {
      if (c.grey) return {c.grey->width(), c.grey->height()};
      if (c.rgb) return {c.rgb->width(), c.rgb->height()};
    }
  AO_ASSERT(false && "a contact sheet without images");
  return {0, 0};
}

// One row: its label (when there is a font) above its images, an empty cell left as background.
Image<Vec3> row_band(const SheetRow& row, std::size_t columns, int w, int h, const Layout* l) {
  std::vector<std::string> lines;
  if (l != nullptr) lines = wrap(l->font, l->px, row.label, kLabelJoiner, l->sheet_w - 2 * kGap);
  const int label_h = lines.empty() ? 0 : l->pad + static_cast<int>(lines.size()) * l->line + l->pad / 4;
  const int col_w = l != nullptr ? l->col_w : w;
  Image<Vec3> band(sheet_width(columns, col_w), label_h + h, kBackground);
  for (std::size_t i = 0; i < lines.size(); ++i)
    draw_text(l->font, band, kGap, l->pad + static_cast<int>(i) * l->line, lines[i], l->px, kLabelColour);
  for (std::size_t c = 0; c < row.cells.size() && c < columns; ++c) {
    const int x = column_x(static_cast<int>(c), col_w);
    if (row.cells[c].grey) paste(band, x, label_h, *row.cells[c].grey);
    if (row.cells[c].rgb) paste(band, x, label_h, *row.cells[c].rgb);
    if (row.coverage != nullptr && (row.cells[c].grey || row.cells[c].rgb)) mark_background(band, x, label_h, *row.coverage);
  }
  return band;
}

}  // namespace

Image<Vec3> contact_sheet(std::span<const SheetColumn> columns, std::span<const SheetRow> rows, float heat_range, const Font* font) {
  AO_ASSERT(!rows.empty() && !columns.empty() && heat_range > 0);
  const auto [w, h] = image_size(rows);

  std::vector<Image<Vec3>> bands;
  if (font != nullptr) {
    const int px = text_pixels(w);
    const Scale scale = scale_of(*font, px, heat_range);
    int col_w = std::max(w, scale.min_width);
    for (const SheetColumn& c : columns)
      for (const std::string& piece : c.title) col_w = std::max(col_w, text_width(*font, piece, px));
    const Layout layout{*font, px, line_height(*font, px), px / 2, col_w, sheet_width(columns.size(), col_w)};
    bands.push_back(header_band(layout, columns, scale, w, heat_range));
    for (const SheetRow& row : rows) bands.push_back(row_band(row, columns.size(), w, h, &layout));
  } else {
    for (const SheetRow& row : rows) bands.push_back(row_band(row, columns.size(), w, h, nullptr));
  }

  int height = kGap;
  for (const Image<Vec3>& b : bands) height += b.height() + kGap;
  Image<Vec3> sheet(bands[0].width(), height, kBackground);
  int y = kGap;
  for (const Image<Vec3>& b : bands) {
    paste(sheet, 0, y, b);
    y += b.height() + kGap;
  }
  return sheet;
}

}  // namespace ao
