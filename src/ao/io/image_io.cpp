// SPDX-License-Identifier: Apache-2.0
#include "ao/io/image_io.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <png.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <memory>
#include <vector>

#include "ao/core/closest_name.h"
#include "ao/core/error.h"
#include "ao/io/atomic_file.h"
#include "ao/io/exr_common_internal.h"
#include "ao/io/image_formats_internal.h"

namespace ao {

namespace fs = std::filesystem;
using namespace io_detail;

static_assert(sizeof(Vec3) == 3 * sizeof(float), "Vec3 images are handed to OpenEXR as interleaved floats");

namespace {

enum class Format { Exr, Png, Tga, Tiff, Jpeg };

std::string lower_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

Format output_format(const fs::path& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".exr") return Format::Exr;
  if (ext == ".png") return Format::Png;
  if (ext == ".tga") return Format::Tga;
  if (ext == ".tif" || ext == ".tiff") return Format::Tiff;
  if (ext == ".jpg" || ext == ".jpeg") return Format::Jpeg;
  throw InputError(path.string() + ": unsupported image format '" + ext + "'; supported: " + supported_image_extensions() + did_you_mean(ext, supported_image_extensions()));
}

// IEC 61966-2-1 decoding (encoding: io_detail::quantise).
float srgb_decode(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

// ---------------------------------------------------------------------------------------------
// libpng reports errors by longjmp. C++ allows longjmp only where a throw to the same place would
// run no non-trivial destructors, so the functions that call setjmp below hold no C++ objects of
// their own: buffers belong to their callers and are sized before or outside the jumps.

struct PngMessage {
  char text[256] = {};
};

void on_png_error(png_structp png, png_const_charp message) {
  auto* m = static_cast<PngMessage*>(png_get_error_ptr(png));
  std::snprintf(m->text, sizeof m->text, "%s", message);
  png_longjmp(png, 1);
}
void on_png_warning(png_structp, png_const_charp) {}  // benign (bad ancillary chunks): ignore

// Interleaved samples, big-endian when 16-bit, exactly as stored in PNG rows.
struct PngPixels {
  png_uint_32 width = 0, height = 0;
  int channels = 0;  // 1 (grey) or 3 (RGB); with alpha kept also 2 (grey + alpha) or 4 (RGBA)
  int bits = 0;      // 8 or 16
  std::vector<unsigned char> bytes;
  std::vector<png_bytep> rows;

  void point_rows() {
    const std::size_t stride = static_cast<std::size_t>(width) * channels * (bits / 8);
    rows.resize(height);
    for (png_uint_32 y = 0; y < height; ++y) rows[y] = bytes.data() + y * stride;
  }
};

int png_color_type(int channels) {
  switch (channels) {
    case 1: return PNG_COLOR_TYPE_GRAY;
    case 2: return PNG_COLOR_TYPE_GRAY_ALPHA;
    case 3: return PNG_COLOR_TYPE_RGB;
    default: return PNG_COLOR_TYPE_RGB_ALPHA;
  }
}

bool write_png_stream(std::FILE* fp, PngPixels& pixels, bool srgb, PngMessage& message) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &message, on_png_error, on_png_warning);
  if (png == nullptr) return false;
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, fp);
  png_set_IHDR(png, info, pixels.width, pixels.height, pixels.bits, png_color_type(pixels.channels),
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (srgb) png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  png_write_info(png, info);
  png_write_image(png, pixels.rows.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

enum class PngReadResult { Ok, Corrupt, TooLarge, OutOfMemory };

PngReadResult read_png_stream(std::FILE* fp, PngPixels& pixels, PngMessage& message, bool keep_alpha) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &message, on_png_error, on_png_warning);
  if (png == nullptr) return PngReadResult::OutOfMemory;
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    return PngReadResult::OutOfMemory;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return PngReadResult::Corrupt;
  }
  png_init_io(png, fp);
  png_read_info(png, info);
  // Size check from the header, before libpng or we allocate anything in proportion to it.
  const png_uint_32 w = png_get_image_width(png, info);
  const png_uint_32 h = png_get_image_height(png, info);
  if (w > kMaxImageSide || h > kMaxImageSide || std::int64_t{w} * h > kMaxImagePixels) {
    pixels.width = w;
    pixels.height = h;
    png_destroy_read_struct(&png, &info, nullptr);
    return PngReadResult::TooLarge;
  }
  // Normalise every colour type to grey or RGB at 8 or 16 bits: palettes and low bit depths are
  // expanded, alpha is dropped (AO maps carry no meaning in it) unless `keep_alpha` (then a tRNS
  // chunk becomes an alpha channel).
  png_set_expand(png);
  if (!keep_alpha) png_set_strip_alpha(png);
  png_read_update_info(png, info);
  pixels.width = w;
  pixels.height = h;
  pixels.channels = png_get_channels(png, info);
  pixels.bits = png_get_bit_depth(png, info);
  const bool supported = (pixels.channels == 1 || pixels.channels == 3 || (keep_alpha && (pixels.channels == 2 || pixels.channels == 4))) &&
                         (pixels.bits == 8 || pixels.bits == 16) &&
                         png_get_rowbytes(png, info) == static_cast<std::size_t>(w) * pixels.channels * (pixels.bits / 8);
  if (!supported) png_error(png, "unsupported pixel layout");
  try {
    pixels.bytes.resize(static_cast<std::size_t>(h) * png_get_rowbytes(png, info));
    pixels.point_rows();
  } catch (const std::bad_alloc&) {
    png_destroy_read_struct(&png, &info, nullptr);
    return PngReadResult::OutOfMemory;
  }
  png_read_image(png, pixels.rows.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return PngReadResult::Ok;
}

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

// Samples (channels per pixel: 1 or 3) quantised to PNG's 8 or 16 bits.
PngPixels quantised_pixels(int width, int height, int channels, const float* samples, const ImageWriteOptions& opt) {
  PngPixels pixels;
  pixels.width = static_cast<png_uint_32>(width);
  pixels.height = static_cast<png_uint_32>(height);
  pixels.channels = channels;
  pixels.bits = opt.png_bits;
  const std::size_t count = static_cast<std::size_t>(width) * height * channels;
  const float max_code = opt.png_bits == 16 ? 65535.0f : 255.0f;
  pixels.bytes.resize(count * (opt.png_bits / 8));
  for (std::size_t i = 0; i < count; ++i) {
    const unsigned code = quantise(samples[i], opt.srgb, max_code);
    if (opt.png_bits == 16) {
      pixels.bytes[2 * i] = static_cast<unsigned char>(code >> 8);  // PNG stores 16-bit samples big-endian
      pixels.bytes[2 * i + 1] = static_cast<unsigned char>(code & 0xffu);
    } else {
      pixels.bytes[i] = static_cast<unsigned char>(code);
    }
  }
  pixels.point_rows();
  return pixels;
}

// Writes `pixels` as the PNG `path`, atomically.
void write_png_file(const fs::path& path, PngPixels& pixels, bool srgb) {
  write_file_atomically(path, [&](const fs::path& temp) {
    FilePtr fp(open_temporary(temp, path));
    PngMessage message;
    if (!write_png_stream(fp.get(), pixels, srgb, message))
      throw SystemError(path.string() + ": cannot write PNG: " + one_line(message.text[0] ? message.text : "out of memory"));
    close_temporary(fp.release(), path);
  });
}

// The PNG write_png_file would write, in memory (a stdio stream over a growing buffer, so the
// encoder and its settings are the same).
std::string encode_png_bytes(PngPixels& pixels, bool srgb) {
  char* buffer = nullptr;
  std::size_t size = 0;
  std::FILE* stream = ::open_memstream(&buffer, &size);
  if (stream == nullptr) throw std::bad_alloc();
  PngMessage message;
  const bool written = write_png_stream(stream, pixels, srgb, message);
  const bool closed = std::fclose(stream) == 0;
  std::string bytes = written && closed ? std::string(buffer, size) : std::string();
  std::free(buffer);
  if (!written || !closed) throw std::bad_alloc();  // a stream in memory fails only for want of it
  return bytes;
}

PngPixels read_png(const fs::path& path, bool keep_alpha = false) {
  FilePtr fp(std::fopen(path.c_str(), "rb"));
  if (!fp) throw InputError(path.string() + ": cannot open for reading");
  PngPixels pixels;
  PngMessage message;
  switch (read_png_stream(fp.get(), pixels, message, keep_alpha)) {
    case PngReadResult::Ok:
      return pixels;
    case PngReadResult::TooLarge:
      check_image_size(path, pixels.width, pixels.height, "image");  // throws with the sizes
      throw InputError(path.string() + ": image too large");
    case PngReadResult::OutOfMemory:
      throw SystemError(path.string() + ": out of memory while reading");
    case PngReadResult::Corrupt:
      break;
  }
  // libpng reports a short file only as "Read Error"; the stream knows better.
  if (std::feof(fp.get())) throw InputError(path.string() + ": truncated PNG: the file ends before the image does");
  throw InputError(path.string() + ": corrupt PNG: " + one_line(message.text));
}

float png_sample(const PngPixels& p, std::size_t index, const ImageReadOptions& opt) {
  const float v = p.bits == 16 ? static_cast<float>((p.bytes[2 * index] << 8) | p.bytes[2 * index + 1]) / 65535.0f
                               : static_cast<float>(p.bytes[index]) / 255.0f;
  return opt.srgb ? srgb_decode(v) : v;
}

// ---------------------------------------------------------------------------------------------
// OpenEXR.

void write_exr(const fs::path& path, int width, int height, std::span<const std::string> names, const float* samples) {
  Imf::Header header(width, height);
  header.compression() = Imf::ZIP_COMPRESSION;  // lossless, and what compositors expect
  Imf::FrameBuffer frame;
  const std::size_t channels = names.size();
  const std::size_t x_stride = channels * sizeof(float);
  for (std::size_t c = 0; c < channels; ++c) {
    header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
    // OpenEXR's Slice takes a non-const pointer for reading and writing alike; writing only reads it.
    frame.insert(names[c], Imf::Slice(Imf::FLOAT, const_cast<char*>(reinterpret_cast<const char*>(samples + c)), x_stride,
                                      x_stride * static_cast<std::size_t>(width)));
  }
  write_exr_atomically(path, header, frame);
}

// Channel read_image takes from an EXR: Y, else R, else the first in name order.
std::string single_channel_name(const Imf::ChannelList& channels) {
  if (channels.findChannel("Y") != nullptr) return "Y";
  if (channels.findChannel("R") != nullptr) return "R";
  return channels.begin().name();
}

void check_sampling(const Imf::ChannelList& channels, const fs::path& path) {
  if (channels.begin() == channels.end()) throw InputError(path.string() + ": OpenEXR file has no channels");
  for (auto it = channels.begin(); it != channels.end(); ++it)
    if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
      throw InputError(path.string() + ": channel '" + it.name() + "' is subsampled, which is not supported");
}

Image<float> read_exr_single(const fs::path& path) {
  return with_exr_errors(path, "not a readable OpenEXR file", [&] {
    Imf::InputFile file(path.c_str());
    const ExrWindows w = exr_windows(file.header(), path);
    check_sampling(file.header().channels(), path);
    Image<float> image(w.width, w.height, 0.0f);
    const ExrChannelTarget target{single_channel_name(file.header().channels()), Imf::FLOAT, image.data()};
    read_exr_channels(file, w, std::span(&target, 1));
    return image;
  });
}

Image<Vec3> read_exr_rgb(const fs::path& path) {
  return with_exr_errors(path, "not a readable OpenEXR file", [&] {
    Imf::InputFile file(path.c_str());
    const ExrWindows w = exr_windows(file.header(), path);
    const Imf::ChannelList& channels = file.header().channels();
    check_sampling(channels, path);
    Image<Vec3> image(w.width, w.height);
    const bool has_rgb = channels.findChannel("R") || channels.findChannel("G") || channels.findChannel("B");
    if (!has_rgb) {
      Image<float> grey(w.width, w.height, 0.0f);
      const ExrChannelTarget target{single_channel_name(channels), Imf::FLOAT, grey.data()};
      read_exr_channels(file, w, std::span(&target, 1));
      for (std::size_t i = 0; i < grey.size(); ++i) image[i] = {grey[i], grey[i], grey[i]};
      return image;
    }
    std::vector<Image<float>> planes;
    std::vector<ExrChannelTarget> targets;
    planes.reserve(3);
    for (const char* name : {"R", "G", "B"}) {
      planes.emplace_back(w.width, w.height, 0.0f);  // a missing channel reads as 0
      if (channels.findChannel(name)) targets.push_back({name, Imf::FLOAT, planes.back().data()});
    }
    read_exr_channels(file, w, targets);
    for (std::size_t i = 0; i < image.size(); ++i) image[i] = {planes[0][i], planes[1][i], planes[2][i]};
    return image;
  });
}

// Checks the file and tells which reader to use, by content.
Format input_format(const fs::path& path) {
  require_input_file(path);
  const std::string magic = read_magic(path, 8);
  if (is_exr_magic(magic)) return Format::Exr;
  if (is_png_magic(magic)) return Format::Png;
  throw InputError(path.string() + ": not an image this tool reads (expected OpenEXR or PNG content)");
}

// PNG here; TGA, TIFF and JPEG in image_formats.cpp.
void write_8_or_16_bit(const fs::path& path, Format format, int width, int height, int channels, const float* samples, const ImageWriteOptions& opt) {
  if (format == Format::Png) {
    PngPixels pixels = quantised_pixels(width, height, channels, samples, opt);
    return write_png_file(path, pixels, opt.srgb);
  }
  // The formats' own limits: 16-bit sizes in the TGA header, JPEG_MAX_DIMENSION in libjpeg.
  const int max_side = format == Format::Tga ? 65535 : format == Format::Jpeg ? 65500 : 1 << 30;
  if (width > max_side || height > max_side)
    throw InputError(path.string() + ": " + std::to_string(width) + "x" + std::to_string(height) + " is too large for " + lower_extension(path) + " (at most " +
                     std::to_string(max_side) + " per side)");
  write_file_atomically(path, [&](const fs::path& temp) {
    switch (format) {
      case Format::Tga: return write_tga_file(path, temp, width, height, channels, samples, opt.srgb);
      case Format::Tiff: return write_tiff_file(path, temp, width, height, channels, samples, opt.png_bits, opt.srgb);
      default: return write_jpeg_file(path, temp, width, height, channels, samples, opt.jpeg_quality, opt.srgb);
    }
  });
}

template <class T>
void require_nonempty(const fs::path& path, const Image<T>& image) {
  if (image.width() < 1 || image.height() < 1) throw InputError(path.string() + ": cannot write an empty image");
}

}  // namespace

void ImageWriteOptions::validate() const {
  if (png_bits != 8 && png_bits != 16) throw InputError("png_bits must be 8 or 16, got " + std::to_string(png_bits));
  if (jpeg_quality < 1 || jpeg_quality > 100) throw InputError("jpeg_quality must be in [1, 100], got " + std::to_string(jpeg_quality));
  if (exr_channel.empty()) throw InputError("exr_channel must not be empty");
}

std::string supported_image_extensions() { return ".exr, .png, .tif, .tiff, .tga, .jpg, .jpeg"; }

bool is_supported_image_path(const fs::path& path) {
  const std::string ext = lower_extension(path);
  return ext == ".exr" || ext == ".png" || ext == ".tif" || ext == ".tiff" || ext == ".tga" || ext == ".jpg" || ext == ".jpeg";
}

void write_image(const fs::path& path, const Image<float>& image, const ImageWriteOptions& opt) {
  const Format format = output_format(path);
  opt.validate();
  require_nonempty(path, image);
  if (format == Format::Exr) {
    const std::string name = opt.exr_channel;
    write_exr(path, image.width(), image.height(), std::span(&name, 1), image.data());
  } else {
    write_8_or_16_bit(path, format, image.width(), image.height(), 1, image.data(), opt);
  }
}

void write_rgb_image(const fs::path& path, const Image<Vec3>& image, const ImageWriteOptions& opt) {
  const Format format = output_format(path);
  opt.validate();
  require_nonempty(path, image);
  const float* samples = reinterpret_cast<const float*>(image.data());
  if (format == Format::Exr) {
    const std::string names[] = {"R", "G", "B"};
    write_exr(path, image.width(), image.height(), names, samples);
  } else {
    write_8_or_16_bit(path, format, image.width(), image.height(), 3, samples, opt);
  }
}

Image<float> read_image(const fs::path& path, const ImageReadOptions& opt) {
  if (input_format(path) == Format::Exr) return read_exr_single(path);
  const PngPixels p = read_png(path);
  Image<float> image(static_cast<int>(p.width), static_cast<int>(p.height));
  for (std::size_t i = 0; i < image.size(); ++i) image[i] = png_sample(p, i * p.channels, opt);  // grey, or R of RGB
  return image;
}

Image<Vec3> read_rgb_image(const fs::path& path, const ImageReadOptions& opt) {
  if (input_format(path) == Format::Exr) return read_exr_rgb(path);
  const PngPixels p = read_png(path);
  Image<Vec3> image(static_cast<int>(p.width), static_cast<int>(p.height));
  for (std::size_t i = 0; i < image.size(); ++i) {
    if (p.channels == 1) {
      const float v = png_sample(p, i, opt);
      image[i] = {v, v, v};
    } else {
      image[i] = {png_sample(p, 3 * i, opt), png_sample(p, 3 * i + 1, opt), png_sample(p, 3 * i + 2, opt)};
    }
  }
  return image;
}

StoredPng read_stored_png(const fs::path& path) {
  require_input_file(path);
  if (!is_png_magic(read_magic(path, 8))) throw InputError(path.string() + ": not a PNG file");
  const PngPixels p = read_png(path, true);
  StoredPng out;
  out.width = static_cast<int>(p.width);
  out.height = static_cast<int>(p.height);
  out.channels = p.channels;
  out.bits = p.bits;
  const std::size_t count = static_cast<std::size_t>(p.width) * p.height * static_cast<std::size_t>(p.channels);
  out.samples.resize(count);
  for (std::size_t i = 0; i < count; ++i)
    out.samples[i] = p.bits == 16 ? static_cast<std::uint16_t>((p.bytes[2 * i] << 8) | p.bytes[2 * i + 1]) : p.bytes[i];
  return out;
}

namespace {

// A StoredPng's layout checked (InputError naming `path`) and its samples as PNG rows.
PngPixels stored_pixels(const fs::path& path, const StoredPng& image) {
  const bool layout_ok = image.width >= 1 && image.height >= 1 && image.channels >= 1 && image.channels <= 4 && (image.bits == 8 || image.bits == 16) &&
                         image.samples.size() == static_cast<std::size_t>(image.width) * image.height * static_cast<std::size_t>(image.channels);
  if (!layout_ok) throw InputError(path.string() + ": cannot write a PNG of " + std::to_string(image.width) + "x" + std::to_string(image.height) + ", " +
                                   std::to_string(image.channels) + " channels, " + std::to_string(image.bits) + " bits from " +
                                   std::to_string(image.samples.size()) + " samples");
  PngPixels pixels;
  pixels.width = static_cast<png_uint_32>(image.width);
  pixels.height = static_cast<png_uint_32>(image.height);
  pixels.channels = image.channels;
  pixels.bits = image.bits;
  pixels.bytes.resize(image.samples.size() * static_cast<std::size_t>(image.bits / 8));
  for (std::size_t i = 0; i < image.samples.size(); ++i) {
    if (image.bits == 16) {
      pixels.bytes[2 * i] = static_cast<unsigned char>(image.samples[i] >> 8);  // big-endian, as PNG stores it
      pixels.bytes[2 * i + 1] = static_cast<unsigned char>(image.samples[i] & 0xffu);
    } else {
      pixels.bytes[i] = static_cast<unsigned char>(image.samples[i]);
    }
  }
  pixels.point_rows();
  return pixels;
}

}  // namespace

void write_stored_png(const fs::path& path, const StoredPng& image) {
  PngPixels pixels = stored_pixels(path, image);
  if (lower_extension(path) != ".png") throw InputError(path.string() + ": this image is written as PNG; give it a .png name");
  write_png_file(path, pixels, false);
}

std::string encode_stored_png(const StoredPng& image) {
  PngPixels pixels = stored_pixels("the PNG", image);
  return encode_png_bytes(pixels, false);
}

std::string encode_png(const Image<float>& image, const ImageWriteOptions& opt) {
  opt.validate();
  if (image.width() < 1 || image.height() < 1) throw InputError("encode_png: the image is empty");
  PngPixels pixels = quantised_pixels(image.width(), image.height(), 1, image.data(), opt);
  return encode_png_bytes(pixels, opt.srgb);
}

void replace_channel(StoredPng& image, int channel, const Image<float>& values) {
  if (channel < 0 || channel >= image.channels) throw InputError("replace_channel: channel " + std::to_string(channel) + " of a " + std::to_string(image.channels) + "-channel image");
  if (values.width() != image.width || values.height() != image.height)
    throw InputError("replace_channel: values are " + std::to_string(values.width()) + "x" + std::to_string(values.height()) + ", the image " +
                     std::to_string(image.width) + "x" + std::to_string(image.height));
  const float max_code = image.bits == 16 ? 65535.0f : 255.0f;
  for (std::size_t i = 0; i < values.size(); ++i)
    image.samples[i * static_cast<std::size_t>(image.channels) + static_cast<std::size_t>(channel)] = static_cast<std::uint16_t>(quantise(values[i], false, max_code));
}

}  // namespace ao
