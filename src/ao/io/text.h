// SPDX-License-Identifier: Apache-2.0
// Text on images: anti-aliased glyphs from a TrueType/OpenType font (FreeType), blended over an RGB
// image. Used to label `ao compare`'s contact sheet. A font is a file read at run time, so a missing
// one is reported, not thrown: a picture without labels is better than no picture.
//
// Geometry: a string occupies a box `text_width` pixels wide and `line_height` pixels tall; (x, y) in
// draw_text is the box's top-left corner and the baseline lies `ascender` pixels below it. Every
// pixel draw_text changes lies inside that box (ink beyond the font's ascender or descender, such as
// stacked accents, is clipped to it) and inside the image.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "ao/core/image.h"
#include "ao/core/math.h"

namespace ao {

/// Where Debian's fonts-dejavu-core puts DejaVu Sans, the font of the contact sheet's labels.
inline constexpr const char* kDejaVuSansPath = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

/// A font face opened with FreeType. Movable, not copyable; not thread-safe (one thread draws at a time).
class Font {
 public:
  /// Opens the font file at `path`. Returns no font, and puts one line naming the file and the
  /// problem in `*error` (when given), if the file is missing or FreeType cannot read it as a font
  /// with a Unicode character map. Never throws for a bad file.
  static std::optional<Font> open(const std::filesystem::path& path, std::string* error = nullptr);

  Font(Font&&) noexcept;
  Font& operator=(Font&&) noexcept;
  ~Font();

 private:
  struct Impl;
  explicit Font(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;

  friend int text_width(const Font&, std::string_view, int);
  friend int line_height(const Font&, int);
  friend int ascender(const Font&, int);
  friend void draw_text(const Font&, Image<Vec3>&, int, int, std::string_view, int, Vec3);
};

/// Smallest and largest `pixel_height` accepted; others are an InputError.
inline constexpr int kMinTextPixels = 1, kMaxTextPixels = 1024;

/// Width in pixels of the box `text` (UTF-8; invalid bytes show as U+FFFD) occupies at `pixel_height`
/// (the font's em size in pixels): from the leftmost ink or the pen's start, whichever is further
/// left, to the rightmost ink or the pen's end. 0 for an empty string.
int text_width(const Font& font, std::string_view text, int pixel_height);

/// Height in pixels of one line of text at `pixel_height`: ascender + descender, rounded up.
/// About 1.17 x pixel_height for DejaVu Sans.
int line_height(const Font& font, int pixel_height);

/// Distance in pixels from the top of the line box to the baseline.
int ascender(const Font& font, int pixel_height);

/// Draws `text` with its box's top-left corner at (x, y) (pixels, may be partly or wholly off the
/// image), blending `colour` over the image by each pixel's glyph coverage in [0,1]:
/// out = in + (colour - in) x coverage. Only pixels inside the text box and the image change;
/// an empty string changes nothing.
void draw_text(const Font& font, Image<Vec3>& image, int x, int y, std::string_view text, int pixel_height, Vec3 colour);

}  // namespace ao
