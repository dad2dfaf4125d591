// SPDX-License-Identifier: Apache-2.0
// Writers of the 8/16-bit interchange formats besides PNG and EXR (image_io.cpp dispatches by
// extension): TGA (hand-written, 8 bit), TIFF (libtiff, 8/16 bit, Deflate) and JPEG (libjpeg,
// 8 bit, lossy). Samples are linear floats, `channels` per pixel (1 grey or 3 RGB), row 0 the top
// of the image; they are clamped to [0,1] (NaN -> 0) and quantised by rounding. Each writes the
// whole file to `temp` and throws SystemError naming `path` (the destination) when the library or
// the disk fails; sizes are checked by the caller (TGA and JPEG hold at most 65535 x 65535). Not public API.
#pragma once

#include <filesystem>

namespace ao::io_detail {

/// Quantises a sample as the PNG writer does: clamp to [0,1] (NaN -> 0), optional sRGB encoding,
/// round to 0..max_code.
unsigned quantise(float v, bool srgb, float max_code);

/// Uncompressed TGA (image type 3 grey or 2 BGR), 8 bits per sample, top-left origin.
void write_tga_file(const std::filesystem::path& path, const std::filesystem::path& temp, int width, int height, int channels, const float* samples, bool srgb);
/// TIFF, `bits` 8 or 16 per sample, Deflate-compressed with horizontal differencing, one strip per 64 rows.
void write_tiff_file(const std::filesystem::path& path, const std::filesystem::path& temp, int width, int height, int channels, const float* samples, int bits, bool srgb);
/// Baseline JPEG (8 bits, 4:4:4, `quality` in [1, 100]).
void write_jpeg_file(const std::filesystem::path& path, const std::filesystem::path& temp, int width, int height, int channels, const float* samples, int quality, bool srgb);

}  // namespace ao::io_detail
