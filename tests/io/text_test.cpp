// SPDX-License-Identifier: Apache-2.0
// Text on images: ink lands inside the box text_width x line_height reports and nowhere else, the
// box is tight, blending follows coverage, and a missing or broken font is reported, not thrown.
// The font is the DejaVu Sans that scripts/setup installs; the tests that draw skip without it.
#include "ao/io/text.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <optional>
#include <string>

#include "ao/core/error.h"
#include "support/run.h"

namespace ao {
namespace {

namespace fs = std::filesystem;

class Text : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string error;
    font_ = Font::open(kDejaVuSansPath, &error);
    if (!font_) GTEST_SKIP() << error << " (scripts/setup installs fonts-dejavu-core)";
  }
  std::optional<Font> font_;
};

bool inked(const Image<Vec3>& img, int x, int y) { return img(x, y).x != 0 || img(x, y).y != 0 || img(x, y).z != 0; }

// Draws white on black and checks every pixel: ink only inside the reported box, and ink reaching
// near each side of it, so the box is not merely large.
void expect_ink_fills_box_exactly(const Font& font, const std::string& text, int px, int bx, int by) {
  SCOPED_TRACE(text + " at " + std::to_string(px) + " px");
  Image<Vec3> img(400, 120);
  draw_text(font, img, bx, by, text, px, Vec3{1, 1, 1});
  const int w = text_width(font, text, px), h = line_height(font, px);
  ASSERT_GT(w, 0);
  int min_x = img.width(), max_x = -1, min_y = img.height(), max_y = -1;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) {
      if (!inked(img, x, y)) continue;
      const bool inside = x >= bx && x < bx + w && y >= by && y < by + h;
      ASSERT_TRUE(inside) << "ink at (" << x << ", " << y << "), box " << w << "x" << h << " at (" << bx << ", " << by << ")";
      min_x = std::min(min_x, x), max_x = std::max(max_x, x), min_y = std::min(min_y, y), max_y = std::max(max_y, y);
    }
  ASSERT_GE(max_x, 0) << "no ink at all";
  // Side bearings are at most about 0.1 em (the period's), so ink comes within that of each side;
  // ascenders and descenders ("H", "g", or digits at 0.73 em) come within a quarter of the line.
  const int bearing = 2 + px / 8;
  EXPECT_LE(min_x - bx, bearing);
  EXPECT_LE(bx + w - 1 - max_x, bearing);
  EXPECT_LE(min_y - by, h / 4);
  EXPECT_LE(by + h - 1 - max_y, h / 4);
}

TEST_F(Text, InkStaysInsideTheReportedBox) {
  for (int px : {9, 12, 20, 32})
    for (const std::string text : {"Hello, gjpqy", "joy", "W.", "RMSE 0.1303", "-0.25 0 +0.25"}) expect_ink_fills_box_exactly(*font_, text, px, 17, 9);
}

TEST_F(Text, LineHeightAndAscenderScaleWithSize) {
  EXPECT_LT(line_height(*font_, 12), line_height(*font_, 24));
  // DejaVu Sans: ascender 0.93 em, descender 0.24 em, so a line is about 1.17 em.
  EXPECT_NEAR(line_height(*font_, 100), 117, 3);
  EXPECT_GT(ascender(*font_, 20), 20 / 2);
  EXPECT_LT(ascender(*font_, 20), line_height(*font_, 20));
}

TEST_F(Text, LongerTextIsWider) {
  EXPECT_LT(text_width(*font_, "abc", 16), text_width(*font_, "abcd", 16));
  EXPECT_LT(text_width(*font_, "iii", 16), text_width(*font_, "WWW", 16));
  EXPECT_LT(text_width(*font_, "abc", 12), text_width(*font_, "abc", 24));
}

TEST_F(Text, EmptyStringDrawsNothing) {
  Image<Vec3> img(64, 32, Vec3{0.25f, 0.5f, 0.75f});
  const Image<Vec3> before = img;
  draw_text(*font_, img, 3, 4, "", 16, Vec3{1, 0, 0});
  EXPECT_EQ(text_width(*font_, "", 16), 0);
  for (std::size_t i = 0; i < img.size(); ++i) ASSERT_EQ(img[i], before[i]) << i;
}

TEST_F(Text, BlendsColourByCoverage) {
  const Vec3 background{0.2f, 0.4f, 0.6f}, red{1, 0, 0};
  Image<Vec3> img(200, 60, background);
  draw_text(*font_, img, 5, 5, "HHH mmm", 32, red);
  int full = 0, partial = 0;
  for (std::size_t i = 0; i < img.size(); ++i) {
    const Vec3 c = img[i];
    if (c == background) continue;
    // Every changed pixel lies on the segment from the background to the colour.
    const float a = (c.x - background.x) / (red.x - background.x);
    EXPECT_NEAR(c.y, background.y + (red.y - background.y) * a, 1e-5f);
    EXPECT_NEAR(c.z, background.z + (red.z - background.z) * a, 1e-5f);
    if (c == red) ++full;
    else ++partial;
  }
  EXPECT_GT(full, 100) << "the stems of H are fully covered";
  EXPECT_GT(partial, 20) << "the edges are anti-aliased";
}

TEST_F(Text, TextPartlyOffTheImageIsClipped) {
  Image<Vec3> img(40, 20);
  draw_text(*font_, img, -15, -8, "Clipped text", 20, Vec3{1, 1, 1});
  draw_text(*font_, img, 30, 12, "Clipped text", 20, Vec3{1, 1, 1});
  draw_text(*font_, img, 1000, 1000, "far away", 20, Vec3{1, 1, 1});
  int ink = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) ink += inked(img, x, y);
  EXPECT_GT(ink, 0);
}

TEST_F(Text, MalformedUtf8DrawsSomethingInsteadOfFailing) {
  EXPECT_GT(text_width(*font_, "\xff\xfe", 16), 0);
  EXPECT_GT(text_width(*font_, "a\xe2\x82", 16), text_width(*font_, "a", 16));  // truncated sequence
  EXPECT_GT(text_width(*font_, "\xc3\xa9", 16), 0);                             // é
}

TEST_F(Text, PixelHeightOutOfRangeIsAnInputError) {
  EXPECT_THROW(text_width(*font_, "a", 0), InputError);
  EXPECT_THROW(text_width(*font_, "a", kMaxTextPixels + 1), InputError);
}

TEST(TextFont, MissingFontIsReportedNotThrown) {
  std::string error;
  std::optional<Font> font;
  EXPECT_NO_THROW(font = Font::open("/nonexistent/NoSuchFont.ttf", &error));
  EXPECT_FALSE(font.has_value());
  EXPECT_NE(error.find("NoSuchFont.ttf"), std::string::npos) << error;
  EXPECT_NE(error.find("no such font file"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  EXPECT_FALSE(Font::open("/nonexistent/NoSuchFont.ttf").has_value()) << "the message is optional";
}

TEST(TextFont, FilesThatAreNotFontsAreReportedNotThrown) {
  test::TempDir dir;
  for (const auto& [name, content] : {std::pair<std::string, std::string>{"empty.ttf", ""}, {"words.ttf", "not a font at all\n"},
                                      {"truncated.ttf", std::string("\x00\x01\x00\x00\x00\x10", 6)}}) {
    std::string error;
    std::optional<Font> font;
    EXPECT_NO_THROW(font = Font::open(dir.write(name, content), &error)) << name;
    EXPECT_FALSE(font.has_value()) << name;
    EXPECT_NE(error.find(name), std::string::npos) << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  }
  std::string error;
  EXPECT_FALSE(Font::open(dir.path(), &error).has_value()) << "a directory";
  EXPECT_FALSE(error.empty());
}

}  // namespace
}  // namespace ao
