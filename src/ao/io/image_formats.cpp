// SPDX-License-Identifier: Apache-2.0
// TGA, TIFF and JPEG writers (see image_formats_internal.h). Formats:
// - TGA: Truevision TGA 2.0 specification, an 18-byte header (no ID, no colour map), image type 3
//   (uncompressed grey) or 2 (uncompressed true colour, stored B, G, R), descriptor bit 5 set so
//   row 0 is the top of the image.
// - TIFF: baseline TIFF 6.0 greyscale / RGB through libtiff, Adobe Deflate with the horizontal
//   differencing predictor (lossless, the usual compression of 8/16-bit texture TIFFs).
// - JPEG: baseline JPEG through libjpeg(-turbo), no chroma subsampling (a grey AO map is one
//   component; RGB keeps full chroma resolution, since bent normals are data, not a photograph).
#include "ao/io/image_formats_internal.h"

#include <jpeglib.h>
#include <tiffio.h>

#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <memory>

#include <unistd.h>
#include <vector>

#include "ao/core/error.h"
#include "ao/io/atomic_file.h"
#include "ao/io/exr_common_internal.h"

namespace ao::io_detail {

namespace fs = std::filesystem;

namespace {

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

// IEC 61966-2-1 encoding.
float srgb_encode(float v) { return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f; }

std::vector<unsigned char> to_bytes(std::size_t count, const float* samples, bool srgb) {
  std::vector<unsigned char> out(count);
  for (std::size_t i = 0; i < count; ++i) out[i] = static_cast<unsigned char>(quantise(samples[i], srgb, 255.0f));
  return out;
}

void close_checked(FilePtr& fp, const fs::path& path) { close_temporary(fp.release(), path); }

// --- JPEG ---------------------------------------------------------------------------------------
// libjpeg reports errors through error_exit, which must not return: it longjmps back here. As for
// libpng (image_io.cpp), the function calling setjmp owns no C++ objects.

struct JpegError {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char text[JMSG_LENGTH_MAX];
};

void on_jpeg_error(j_common_ptr cinfo) {
  auto* e = reinterpret_cast<JpegError*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, e->text);
  std::longjmp(e->jump, 1);
}

bool write_jpeg_stream(std::FILE* fp, const unsigned char* bytes, int width, int height, int channels, int quality, JpegError& err) {
  jpeg_compress_struct cinfo;
  cinfo.err = jpeg_std_error(&err.mgr);
  err.mgr.error_exit = on_jpeg_error;
  err.text[0] = '\0';
  if (setjmp(err.jump)) {
    jpeg_destroy_compress(&cinfo);
    return false;
  }
  jpeg_create_compress(&cinfo);
  jpeg_stdio_dest(&cinfo, fp);
  cinfo.image_width = static_cast<JDIMENSION>(width);
  cinfo.image_height = static_cast<JDIMENSION>(height);
  cinfo.input_components = channels;
  cinfo.in_color_space = channels == 1 ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_set_defaults(&cinfo);
  jpeg_set_quality(&cinfo, quality, TRUE);
  for (int c = 0; c < cinfo.num_components; ++c) cinfo.comp_info[c].h_samp_factor = cinfo.comp_info[c].v_samp_factor = 1;  // 4:4:4
  jpeg_start_compress(&cinfo, TRUE);
  const std::size_t stride = static_cast<std::size_t>(width) * channels;
  while (cinfo.next_scanline < cinfo.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(bytes + cinfo.next_scanline * stride);  // libjpeg only reads it
    jpeg_write_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_compress(&cinfo);
  jpeg_destroy_compress(&cinfo);
  return true;
}

// --- TIFF ---------------------------------------------------------------------------------------

struct TiffMessage {
  std::string text;
};

int on_tiff_error(TIFF*, void* user, const char* module, const char* fmt, va_list ap) {
  char buf[512];
  std::vsnprintf(buf, sizeof buf, fmt, ap);
  auto* m = static_cast<TiffMessage*>(user);
  if (m->text.empty()) m->text = std::string(module ? module : "libtiff") + ": " + buf;
  return 1;  // handled: libtiff does not print it
}
int on_tiff_warning(TIFF*, void*, const char*, const char*, va_list) { return 1; }

}  // namespace

unsigned quantise(float v, bool srgb, float max_code) {
  // NaN compares false, so it lands on 0 here; the clamp is the documented behaviour of 8/16-bit files.
  float x = v > 0.0f ? std::min(v, 1.0f) : 0.0f;
  if (srgb) x = srgb_encode(x);
  return static_cast<unsigned>(std::lround(x * max_code));
}

void write_tga_file(const fs::path& path, const fs::path& temp, int width, int height, int channels, const float* samples, bool srgb) {
  const std::vector<unsigned char> bytes = to_bytes(static_cast<std::size_t>(width) * height * channels, samples, srgb);
  unsigned char header[18] = {};
  header[2] = channels == 1 ? 3 : 2;  // image type: uncompressed grey / true colour
  header[12] = static_cast<unsigned char>(width & 0xff);
  header[13] = static_cast<unsigned char>(width >> 8);
  header[14] = static_cast<unsigned char>(height & 0xff);
  header[15] = static_cast<unsigned char>(height >> 8);
  header[16] = static_cast<unsigned char>(8 * channels);  // bits per pixel
  header[17] = 0x20;                                      // origin top-left, no alpha bits
  FilePtr fp(open_temporary(temp, path));
  std::fwrite(header, 1, sizeof header, fp.get());
  if (channels == 1) {
    std::fwrite(bytes.data(), 1, bytes.size(), fp.get());
  } else {
    std::vector<unsigned char> bgr(bytes.size());
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
      bgr[i] = bytes[i + 2];
      bgr[i + 1] = bytes[i + 1];
      bgr[i + 2] = bytes[i];
    }
    std::fwrite(bgr.data(), 1, bgr.size(), fp.get());
  }
  close_checked(fp, path);
}

void write_tiff_file(const fs::path& path, const fs::path& temp, int width, int height, int channels, const float* samples, int bits, bool srgb) {
  TiffMessage message;
  std::unique_ptr<TIFFOpenOptions, void (*)(TIFFOpenOptions*)> opts(TIFFOpenOptionsAlloc(), TIFFOpenOptionsFree);
  if (!opts) throw SystemError(path.string() + ": out of memory");
  TIFFOpenOptionsSetErrorHandlerExtR(opts.get(), on_tiff_error, &message);
  TIFFOpenOptionsSetWarningHandlerExtR(opts.get(), on_tiff_warning, nullptr);
  // TIFF gets the descriptor of the temporary file (open_temporary: no symbolic link followed);
  // TIFFClose closes it.
  const int fd = open_temporary_descriptor(temp, path);
  std::unique_ptr<TIFF, void (*)(TIFF*)> tif(TIFFFdOpenExt(fd, temp.c_str(), "w", opts.get()), TIFFClose);
  if (!tif) ::close(fd);
  if (!tif) throw SystemError(path.string() + ": cannot open the temporary file for writing" + (message.text.empty() ? "" : ": " + one_line(message.text)));
  constexpr std::uint32_t kRowsPerStrip = 64;
  TIFF* t = tif.get();
  TIFFSetField(t, TIFFTAG_IMAGEWIDTH, static_cast<std::uint32_t>(width));
  TIFFSetField(t, TIFFTAG_IMAGELENGTH, static_cast<std::uint32_t>(height));
  TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, static_cast<std::uint16_t>(channels));
  TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, static_cast<std::uint16_t>(bits));
  TIFFSetField(t, TIFFTAG_SAMPLEFORMAT, SAMPLEFORMAT_UINT);
  TIFFSetField(t, TIFFTAG_PHOTOMETRIC, channels == 1 ? PHOTOMETRIC_MINISBLACK : PHOTOMETRIC_RGB);
  TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFSetField(t, TIFFTAG_ORIENTATION, ORIENTATION_TOPLEFT);
  TIFFSetField(t, TIFFTAG_COMPRESSION, COMPRESSION_ADOBE_DEFLATE);
  TIFFSetField(t, TIFFTAG_PREDICTOR, PREDICTOR_HORIZONTAL);
  TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, kRowsPerStrip);
  const std::size_t row_samples = static_cast<std::size_t>(width) * channels;
  const float max_code = bits == 16 ? 65535.0f : 255.0f;
  std::vector<std::uint8_t> strip8;
  std::vector<std::uint16_t> strip16;
  for (std::uint32_t y0 = 0; y0 < static_cast<std::uint32_t>(height); y0 += kRowsPerStrip) {
    const std::uint32_t rows = std::min<std::uint32_t>(kRowsPerStrip, static_cast<std::uint32_t>(height) - y0);
    const std::size_t count = row_samples * rows;
    const float* src = samples + row_samples * y0;
    tmsize_t written;
    if (bits == 16) {
      strip16.resize(count);
      for (std::size_t i = 0; i < count; ++i) strip16[i] = static_cast<std::uint16_t>(quantise(src[i], srgb, max_code));
      written = TIFFWriteEncodedStrip(t, y0 / kRowsPerStrip, strip16.data(), static_cast<tmsize_t>(count * 2));
    } else {
      strip8.resize(count);
      for (std::size_t i = 0; i < count; ++i) strip8[i] = static_cast<std::uint8_t>(quantise(src[i], srgb, max_code));
      written = TIFFWriteEncodedStrip(t, y0 / kRowsPerStrip, strip8.data(), static_cast<tmsize_t>(count));
    }
    if (written < 0) throw SystemError(path.string() + ": cannot write TIFF: " + one_line(message.text.empty() ? "write failed (disk full?)" : message.text));
  }
  // TIFFClose writes the directory; a failure there shows as an error message or a flush failure.
  if (!TIFFFlush(t) || !message.text.empty()) throw SystemError(path.string() + ": cannot write TIFF: " + one_line(message.text.empty() ? "write failed (disk full?)" : message.text));
}

void write_jpeg_file(const fs::path& path, const fs::path& temp, int width, int height, int channels, const float* samples, int quality, bool srgb) {
  const std::vector<unsigned char> bytes = to_bytes(static_cast<std::size_t>(width) * height * channels, samples, srgb);
  FilePtr fp(open_temporary(temp, path));
  JpegError err;
  if (!write_jpeg_stream(fp.get(), bytes.data(), width, height, channels, quality, err)) throw SystemError(path.string() + ": cannot write JPEG: " + one_line(err.text));
  close_checked(fp, path);
}

}  // namespace ao::io_detail
