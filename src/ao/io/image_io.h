// SPDX-License-Identifier: Apache-2.0
// Image files: OpenEXR (float32, lossless), PNG and TIFF (8 or 16 bit, lossless), TGA (8 bit) and
// JPEG (8 bit, lossy: for previews, not for data). Reads: EXR and PNG. Writes are atomic
// (atomic_file.h). Reads check the size before allocating and turn every library failure into an
// InputError of one line that names the file.
//
// Conventions:
// - EXR keeps floats exactly, NaN and infinity included (what they mean is the caller's business).
//   A single-channel image is stored as the luminance channel `Y`, the name OpenEXR and compositors
//   use for greyscale. Files are scanline, ZIP-compressed.
// - PNG, TIFF, TGA and JPEG values are linear (values in [0,1] map to 0..255 or 0..65535) and
//   carry no colour-space tag, as AO maps and other data textures conventionally do; with `srgb`
//   they are sRGB-encoded (and a PNG is tagged with an sRGB chunk). Values are clamped to [0,1]
//   and NaN is written as 0. Row 0 is the top of the image in every format.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "ao/core/image.h"
#include "ao/core/math.h"

namespace ao {

/// How images are written.
struct ImageWriteOptions {
  int png_bits = 8;          ///< PNG and TIFF sample depth: 8 or 16. Ignored for EXR, TGA and JPEG (always 8).
  int jpeg_quality = 95;     ///< JPEG quality in [1, 100] (libjpeg's scale); 95 keeps a smooth AO map within ~1/255 of the 8-bit PNG.
  bool srgb = false;         ///< PNG only: sRGB-encode the linear values (for viewing, not for data). Default linear.
  std::string exr_channel = "Y";  ///< EXR channel name of single-channel images; non-empty. Ignored for RGB.

  /// Throws InputError naming the bad field.
  void validate() const;
};

/// How images are read.
struct ImageReadOptions {
  bool srgb = false;  ///< PNG only: the stored values are sRGB-encoded; decode them to linear. Default: stored values as is.
};

/// Comma-separated list of the extensions write_image supports (".exr, .png, ..."), for errors and --help.
std::string supported_image_extensions();
/// True when `path` has an extension write_image understands (case-insensitive).
bool is_supported_image_path(const std::filesystem::path& path);

/// Writes single-channel values (visibility, error maps) to `.exr`, `.png`, `.tif`/`.tiff`,
/// `.tga` or `.jpg`/`.jpeg`, chosen by the extension (case-insensitive). The image must not be empty. Throws InputError for an unknown
/// extension (listing the supported ones), bad options or an empty image, and the errors of
/// write_file_atomically; SystemError when the library fails to write.
void write_image(const std::filesystem::path& path, const Image<float>& image, const ImageWriteOptions& opt = {});

/// Writes RGB values (linear, nominally [0,1]; shaded images, contact sheets): EXR channels R, G, B
/// (float32) or RGB in the 8/16-bit formats. Same rules as write_image.
void write_rgb_image(const std::filesystem::path& path, const Image<Vec3>& image, const ImageWriteOptions& opt = {});

/// Reads one channel as floats. The format is recognised by content, not by extension.
/// - EXR: channel `Y`, else `R`, else the first channel in name order; pixel types are converted to
///   float and values kept as stored. The image is the display window; pixels outside the data
///   window read as 0, OpenEXR's convention.
/// - PNG: greyscale value, or for colour images the red channel (glTF's occlusion-texture convention,
///   so packed occlusion/roughness/metalness maps read correctly); alpha is ignored. Values are
///   normalised to [0,1] and decoded from sRGB only when `opt.srgb`.
/// Throws InputError naming the file and the problem: missing, empty, not an EXR or PNG, truncated
/// or corrupt, more than 32768 pixels per side or 2^28 pixels (checked before allocating).
Image<float> read_image(const std::filesystem::path& path, const ImageReadOptions& opt = {});

/// Reads RGB values. EXR: channels R, G, B (a missing one reads as 0); a file with none of them
/// repeats its single channel (as read_image chooses it) in all three. PNG: greyscale is repeated,
/// alpha ignored. Otherwise as read_image.
Image<Vec3> read_rgb_image(const std::filesystem::path& path, const ImageReadOptions& opt = {});

/// A PNG's samples exactly as stored, to change one channel and write the rest back unchanged
/// (`ao bake --orm`: AO into the red channel of an occlusion/roughness/metalness texture).
struct StoredPng {
  int width = 0, height = 0;
  int channels = 0;                    ///< 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA.
  int bits = 0;                        ///< 8 or 16.
  std::vector<std::uint16_t> samples;  ///< Interleaved codes (0..255 or 0..65535), row 0 at the top.
};

/// Reads a PNG keeping its channels (alpha included) and bit depth. Palette images become RGB (or
/// RGBA with a tRNS chunk) at 8 bits and grey below 8 bits becomes 8 bits; ancillary chunks (text,
/// gamma, colour space) are not kept. Same errors and size limits as read_image.
StoredPng read_stored_png(const std::filesystem::path& path);

/// Writes `image` as a PNG of its channels and depth, with no colour-space chunk, atomically.
/// InputError when the samples do not match the layout or the name does not end in .png.
void write_stored_png(const std::filesystem::path& path, const StoredPng& image);

/// The bytes write_stored_png writes, encoded in memory. InputError when the samples do not match
/// the layout.
std::string encode_stored_png(const StoredPng& image);

/// The bytes write_image writes for a .png name (same encoder, same settings: `opt.png_bits`,
/// `opt.srgb`), encoded in memory: for a PNG embedded in another file (a glTF's occlusion
/// texture), with no file of its own. InputError for an empty image or invalid options.
std::string encode_png(const Image<float>& image, const ImageWriteOptions& opt = {});

/// Replaces channel `channel` of every pixel with `values` (linear, clamped to [0,1], NaN -> 0,
/// rounded to the image's depth). InputError when the channel or the size does not match.
void replace_channel(StoredPng& image, int channel, const Image<float>& values);

}  // namespace ao
