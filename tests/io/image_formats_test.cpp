// SPDX-License-Identifier: Apache-2.0
// TGA, TIFF and JPEG outputs, read back with their reference libraries (libtiff, libjpeg) or, for
// TGA, byte by byte against the format's header layout: exact 8/16-bit quantisation where the
// format is lossless, a stated error bound for JPEG.
#include <gtest/gtest.h>
#include <jpeglib.h>
#include <tiffio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include "ao/core/error.h"
#include "ao/io/image_io.h"
#include "support/run.h"

namespace ao {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A smooth AO-like map: a radial falloff with values over the whole [0,1] range.
Image<float> smooth_map(int w, int h) {
  Image<float> im(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float dx = (x + 0.5f) / w - 0.5f, dy = (y + 0.5f) / h - 0.5f;
      im(x, y) = std::clamp(1.0f - 1.6f * std::sqrt(dx * dx + dy * dy), 0.0f, 1.0f);
    }
  return im;
}

struct Decoded {
  int width = 0, height = 0, channels = 0, bits = 0;
  std::vector<double> values;  // normalised to [0,1], interleaved
};

Decoded read_tiff(const fs::path& path) {
  Decoded d;
  TIFF* t = TIFFOpen(path.c_str(), "r");
  if (!t) return d;
  std::uint32_t w = 0, h = 0;
  std::uint16_t spp = 0, bps = 0, orientation = ORIENTATION_TOPLEFT;
  TIFFGetField(t, TIFFTAG_IMAGEWIDTH, &w);
  TIFFGetField(t, TIFFTAG_IMAGELENGTH, &h);
  TIFFGetField(t, TIFFTAG_SAMPLESPERPIXEL, &spp);
  TIFFGetField(t, TIFFTAG_BITSPERSAMPLE, &bps);
  TIFFGetFieldDefaulted(t, TIFFTAG_ORIENTATION, &orientation);
  d = {static_cast<int>(w), static_cast<int>(h), spp, bps, {}};
  EXPECT_EQ(orientation, ORIENTATION_TOPLEFT);
  std::vector<unsigned char> row(static_cast<std::size_t>(TIFFScanlineSize(t)));
  for (std::uint32_t y = 0; y < h; ++y) {
    if (TIFFReadScanline(t, row.data(), y) < 0) break;
    for (std::size_t i = 0; i < static_cast<std::size_t>(w) * spp; ++i) {
      if (bps == 16) {
        std::uint16_t v;
        std::memcpy(&v, row.data() + 2 * i, 2);
        d.values.push_back(v / 65535.0);
      } else {
        d.values.push_back(row[i] / 255.0);
      }
    }
  }
  TIFFClose(t);
  return d;
}

Decoded read_jpeg(const fs::path& path) {
  Decoded d;
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return d;
  jpeg_decompress_struct cinfo;
  jpeg_error_mgr err;
  cinfo.err = jpeg_std_error(&err);
  jpeg_create_decompress(&cinfo);
  jpeg_stdio_src(&cinfo, f);
  jpeg_read_header(&cinfo, TRUE);
  jpeg_start_decompress(&cinfo);
  d = {static_cast<int>(cinfo.output_width), static_cast<int>(cinfo.output_height), cinfo.output_components, 8, {}};
  std::vector<unsigned char> row(static_cast<std::size_t>(cinfo.output_width) * cinfo.output_components);
  while (cinfo.output_scanline < cinfo.output_height) {
    JSAMPROW r = row.data();
    jpeg_read_scanlines(&cinfo, &r, 1);
    for (unsigned char c : row) d.values.push_back(c / 255.0);
  }
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  std::fclose(f);
  return d;
}

TEST(ImageFormats, TgaHeaderAndPixelsFollowTheSpecification) {
  TempDir dir;
  Image<float> im(3, 2);
  const float v[6] = {0.0f, 0.25f, 0.5f, 0.75f, 1.0f, 2.0f};
  for (int i = 0; i < 6; ++i) im[static_cast<std::size_t>(i)] = v[i];
  write_image(dir / "g.tga", im);
  const std::string g = read_bytes(dir / "g.tga");
  ASSERT_EQ(g.size(), 18u + 6u);
  EXPECT_EQ(g[2], 3);                                  // uncompressed grey
  EXPECT_EQ(static_cast<unsigned char>(g[12]), 3u);    // width, little-endian
  EXPECT_EQ(static_cast<unsigned char>(g[14]), 2u);    // height
  EXPECT_EQ(g[16], 8);                                 // bits per pixel
  EXPECT_EQ(g[17], 0x20);                              // top-left origin
  for (int i = 0; i < 6; ++i)
    EXPECT_EQ(static_cast<unsigned char>(g[18 + static_cast<std::size_t>(i)]), static_cast<unsigned>(std::lround(std::min(v[i], 1.0f) * 255))) << i;
  // RGB is stored B, G, R.
  Image<Vec3> rgb(1, 1, Vec3{1.0f, 0.5f, 0.0f});
  write_rgb_image(dir / "c.tga", rgb);
  const std::string c = read_bytes(dir / "c.tga");
  ASSERT_EQ(c.size(), 18u + 3u);
  EXPECT_EQ(c[2], 2);
  EXPECT_EQ(c[16], 24);
  EXPECT_EQ(static_cast<unsigned char>(c[18]), 0u);
  EXPECT_EQ(static_cast<unsigned char>(c[19]), 128u);
  EXPECT_EQ(static_cast<unsigned char>(c[20]), 255u);
}

TEST(ImageFormats, TiffIsLosslessAt8And16Bits) {
  TempDir dir;
  const Image<float> im = smooth_map(37, 91);  // a height over one 64-row strip, odd width
  for (int bits : {8, 16}) {
    const fs::path p = dir / (bits == 16 ? "m16.tif" : "m8.tif");
    write_image(p, im, {.png_bits = bits});
    const Decoded d = read_tiff(p);
    ASSERT_EQ(d.width, 37);
    ASSERT_EQ(d.height, 91);
    EXPECT_EQ(d.channels, 1);
    EXPECT_EQ(d.bits, bits);
    ASSERT_EQ(d.values.size(), im.size());
    const double step = bits == 16 ? 1.0 / 65535 : 1.0 / 255;
    double worst = 0;
    for (std::size_t i = 0; i < im.size(); ++i) worst = std::max(worst, std::abs(d.values[i] - im[i]));
    EXPECT_LE(worst, 0.5 * step + 1e-7) << bits << " bits";  // rounding to the nearest code
  }
  Image<Vec3> rgb(2, 1);
  rgb[0] = {1, 0, 0};
  rgb[1] = {0, 0.5f, 1};
  write_rgb_image(dir / "c.tiff", rgb);
  const Decoded c = read_tiff(dir / "c.tiff");
  EXPECT_EQ(c.channels, 3);
  ASSERT_EQ(c.values.size(), 6u);
  EXPECT_EQ(c.values[0], 1.0);
  EXPECT_NEAR(c.values[4], 0.5, 0.5 / 255);
}

TEST(ImageFormats, JpegIsLossyWithinAStatedBound) {
  TempDir dir;
  const Image<float> im = smooth_map(64, 48);
  write_image(dir / "m.jpg", im);
  const Decoded d = read_jpeg(dir / "m.jpg");
  ASSERT_EQ(d.width, 64);
  ASSERT_EQ(d.height, 48);
  EXPECT_EQ(d.channels, 1);
  ASSERT_EQ(d.values.size(), im.size());
  double worst = 0, sq = 0;
  for (std::size_t i = 0; i < im.size(); ++i) {
    worst = std::max(worst, std::abs(d.values[i] - im[i]));
    sq += (d.values[i] - im[i]) * (d.values[i] - im[i]);
  }
  // Quality 95 on a smooth map: measured max error 3/255 and RMSE under 1/255 (8-bit rounding
  // alone is 0.5/255 max); a lossless format would be exact to 0.5/255.
  EXPECT_LE(worst, 4.0 / 255);
  EXPECT_LE(std::sqrt(sq / static_cast<double>(im.size())), 1.0 / 255);
  // A lower quality is allowed and loses more.
  write_image(dir / "q10.jpg", im, {.jpeg_quality = 10});
  const Decoded q = read_jpeg(dir / "q10.jpg");
  double worst10 = 0;
  for (std::size_t i = 0; i < im.size(); ++i) worst10 = std::max(worst10, std::abs(q.values[i] - im[i]));
  EXPECT_GT(worst10, worst);
}

TEST(ImageFormats, SizesBeyondTheFormatAreOneLineErrors) {
  TempDir dir;
  const Image<float> wide(65536, 1, 0.5f);
  EXPECT_THROW(write_image(dir / "w.tga", wide), InputError);
  EXPECT_THROW(write_image(dir / "w.jpg", wide), InputError);
  EXPECT_EQ(dir.file_count(), 0);
}

}  // namespace
}  // namespace ao
