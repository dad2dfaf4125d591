// SPDX-License-Identifier: Apache-2.0
// Text on images with FreeType: each glyph is rendered to an 8-bit coverage bitmap (FreeType's
// anti-aliased rasteriser) and blended over the image. See text.h for the box every string occupies.
#include "ao/io/text.h"

#include <ft2build.h>
#include FT_FREETYPE_H

#include <algorithm>
#include <string>
#include <system_error>

#include "ao/core/error.h"

namespace ao {

namespace {

// FreeType measures in 26.6 fixed point (1/64 pixel).
int ceil_pixels(FT_Pos v) { return static_cast<int>((v + 63) >> 6); }
int round_pixels(FT_Pos v) { return static_cast<int>((v + 32) >> 6); }

std::string freetype_message(FT_Error e) {
  // FT_Error_String is null when FreeType was built without its message table.
  const char* s = FT_Error_String(e);
  return s != nullptr ? std::string(s) : "FreeType error " + std::to_string(e);
}

constexpr char32_t kReplacement = 0xFFFD;

// The code point of the UTF-8 sequence starting at s[i], advancing i past it. A malformed,
// overlong or surrogate sequence gives U+FFFD (and consumes what was read of it), so any bytes draw
// something visible instead of failing.
char32_t next_code_point(std::string_view s, std::size_t& i) {
  const auto lead = static_cast<unsigned char>(s[i++]);
  if (lead < 0x80) return lead;
  int extra = 0;
  char32_t cp = 0;
  if ((lead & 0xE0) == 0xC0) {
    extra = 1, cp = lead & 0x1F;
  } else if ((lead & 0xF0) == 0xE0) {
    extra = 2, cp = lead & 0x0F;
  } else if ((lead & 0xF8) == 0xF0) {
    extra = 3, cp = lead & 0x07;
  } else {
    return kReplacement;
  }
  for (int k = 0; k < extra; ++k) {
    if (i >= s.size() || (static_cast<unsigned char>(s[i]) & 0xC0) != 0x80) return kReplacement;
    cp = (cp << 6) | (static_cast<unsigned char>(s[i++]) & 0x3F);
  }
  constexpr char32_t kSmallest[] = {0, 0x80, 0x800, 0x10000};  // below these the sequence is overlong
  if (cp < kSmallest[extra] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return kReplacement;
  return cp;
}

// Coverage in [0,1] of pixel (col, row) of a rendered glyph bitmap. Rendered outlines are 8-bit
// grey (FT_RENDER_MODE_NORMAL); 1-bit bitmaps come only from fonts with embedded monochrome strikes.
float coverage(const FT_Bitmap& b, unsigned col, unsigned row) {
  const unsigned char* line = b.buffer + static_cast<std::ptrdiff_t>(row) * b.pitch;
  if (b.pixel_mode == FT_PIXEL_MODE_MONO) return (line[col / 8] >> (7 - col % 8)) & 1 ? 1.0f : 0.0f;
  if (b.pixel_mode == FT_PIXEL_MODE_GRAY) return static_cast<float>(line[col]) / static_cast<float>(std::max(1, b.num_grays - 1));
  return 0.0f;  // colour (emoji) bitmaps: not drawn
}

}  // namespace

struct Font::Impl {
  FT_Library library = nullptr;
  FT_Face face = nullptr;
  int pixels = 0;  ///< Em size last set on the face; 0 before the first.

  Impl() = default;
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
  ~Impl() {
    if (face != nullptr) FT_Done_Face(face);
    if (library != nullptr) FT_Done_FreeType(library);
  }

  void set_size(int pixel_height) {
    if (pixel_height < kMinTextPixels || pixel_height > kMaxTextPixels)
      throw InputError("text: pixel height " + std::to_string(pixel_height) + " is outside [" + std::to_string(kMinTextPixels) + ", " +
                       std::to_string(kMaxTextPixels) + "]");
    if (pixel_height == pixels) return;
    if (const FT_Error e = FT_Set_Pixel_Sizes(face, 0, static_cast<FT_UInt>(pixel_height)); e != 0)
      throw SystemError("text: cannot set a " + std::to_string(pixel_height) + "-pixel size: " + freetype_message(e));
    pixels = pixel_height;
  }

  // Lays `text` out with the pen starting at x = 0 on a baseline at y = 0 (y pointing down) and
  // calls ink(bitmap, left, top) for each glyph that has a bitmap, (left, top) being its top-left
  // pixel. Returns where the pen ends, in whole pixels rounded up.
  template <class Ink>
  int layout(std::string_view text, int pixel_height, Ink&& ink) {
    set_size(pixel_height);
    FT_Pos pen = 0;
    FT_UInt previous = 0;
    for (std::size_t i = 0; i < text.size();) {
      // Index 0 is the font's own missing-glyph box, so unknown characters stay visible.
      const FT_UInt glyph = FT_Get_Char_Index(face, next_code_point(text, i));
      if (previous != 0 && FT_HAS_KERNING(face)) {
        FT_Vector kern{};
        if (FT_Get_Kerning(face, previous, glyph, FT_KERNING_DEFAULT, &kern) == 0) pen += kern.x;
      }
      previous = glyph;
      if (FT_Load_Glyph(face, glyph, FT_LOAD_RENDER) != 0) continue;  // a broken glyph is left out, not fatal
      const FT_GlyphSlot slot = face->glyph;
      if (slot->bitmap.width > 0 && slot->bitmap.rows > 0) ink(slot->bitmap, round_pixels(pen) + slot->bitmap_left, -slot->bitmap_top);
      pen += slot->advance.x;
    }
    return ceil_pixels(pen);
  }

  struct Extent {
    int left = 0, right = 0;  ///< Pixels from the pen's start; the box is [left, right).
  };
  Extent extent(std::string_view text, int pixel_height) {
    Extent e;
    const int pen_end = layout(text, pixel_height, [&](const FT_Bitmap& b, int left, int) {
      e.left = std::min(e.left, left);
      e.right = std::max(e.right, left + static_cast<int>(b.width));
    });
    e.right = std::max(e.right, pen_end);
    return e;
  }
};

Font::Font(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Font::Font(Font&&) noexcept = default;
Font& Font::operator=(Font&&) noexcept = default;
Font::~Font() = default;

std::optional<Font> Font::open(const std::filesystem::path& path, std::string* error) {
  auto fail = [&](const std::string& problem) -> std::optional<Font> {
    if (error != nullptr) *error = path.string() + ": " + problem;
    return std::nullopt;
  };
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return fail("no such font file");
  auto impl = std::make_unique<Impl>();
  if (const FT_Error e = FT_Init_FreeType(&impl->library); e != 0) return fail("cannot start FreeType: " + freetype_message(e));
  if (const FT_Error e = FT_New_Face(impl->library, path.c_str(), 0, &impl->face); e != 0)
    return fail("not a font FreeType can read (" + freetype_message(e) + ")");
  if (!FT_IS_SCALABLE(impl->face)) return fail("is a bitmap-only font; a scalable (TrueType or OpenType) font is needed");
  if (FT_Select_Charmap(impl->face, FT_ENCODING_UNICODE) != 0) return fail("the font has no Unicode character map");
  return Font(std::move(impl));
}

int text_width(const Font& font, std::string_view text, int pixel_height) {
  const Font::Impl::Extent e = font.impl_->extent(text, pixel_height);
  return e.right - e.left;
}

int ascender(const Font& font, int pixel_height) {
  font.impl_->set_size(pixel_height);
  return ceil_pixels(font.impl_->face->size->metrics.ascender);
}

int line_height(const Font& font, int pixel_height) {
  font.impl_->set_size(pixel_height);
  const FT_Size_Metrics& m = font.impl_->face->size->metrics;
  return ceil_pixels(m.ascender) + ceil_pixels(-m.descender);  // FreeType's descender is negative
}

void draw_text(const Font& font, Image<Vec3>& image, int x, int y, std::string_view text, int pixel_height, Vec3 colour) {
  Font::Impl& f = *font.impl_;
  const Font::Impl::Extent e = f.extent(text, pixel_height);
  // The box, clipped to the image; the pen starts at x - e.left so that the leftmost ink or the
  // pen's start falls on x.
  const int box_x0 = std::max(x, 0), box_x1 = std::min(x + (e.right - e.left), image.width());
  const int box_y0 = std::max(y, 0), box_y1 = std::min(y + line_height(font, pixel_height), image.height());
  if (box_x0 >= box_x1 || box_y0 >= box_y1) return;
  const int pen_x = x - e.left, baseline = y + ascender(font, pixel_height);
  f.layout(text, pixel_height, [&](const FT_Bitmap& b, int left, int top) {
    for (unsigned row = 0; row < b.rows; ++row) {
      const int py = baseline + top + static_cast<int>(row);
      if (py < box_y0 || py >= box_y1) continue;
      for (unsigned col = 0; col < b.width; ++col) {
        const int px = pen_x + left + static_cast<int>(col);
        if (px < box_x0 || px >= box_x1) continue;
        const float a = coverage(b, col, row);
        if (a > 0) image(px, py) += (colour - image(px, py)) * a;
      }
    }
  });
}

}  // namespace ao
