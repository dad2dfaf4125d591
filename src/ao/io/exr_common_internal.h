// SPDX-License-Identifier: Apache-2.0
// Internal helpers shared by image_io.cpp and gbuffer_exr.cpp: checks on input files and sizes,
// and reading OpenEXR channels into display-window images. Not part of the public API.
#pragma once

#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfPixelType.h>

#include <cstdint>
#include <exception>
#include <new>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "ao/core/error.h"
#include "ao/io/io_error_internal.h"

namespace ao::io_detail {

/// Largest accepted image side, pixels: 32k x 32k floats is already 4 GiB, beyond that is a typo
/// or a hostile header.
inline constexpr std::int64_t kMaxImageSide = 32768;
/// Largest accepted pixel count (2^28, 1 GiB per float channel), checked before allocating.
inline constexpr std::int64_t kMaxImagePixels = std::int64_t{1} << 28;

/// Throws InputError naming `path` unless it is an existing, non-empty regular file.
void require_input_file(const std::filesystem::path& path);

/// Throws InputError naming `path` unless 1 <= width, height <= kMaxImageSide and
/// width * height <= kMaxImagePixels. `what` names the thing measured ("image", "data window").
void check_image_size(const std::filesystem::path& path, std::int64_t width, std::int64_t height, std::string_view what);

/// The first bytes of the file: up to `count`, fewer for a shorter file.
std::string read_magic(const std::filesystem::path& path, std::size_t count);
/// True when `magic` starts with OpenEXR's magic number.
bool is_exr_magic(std::string_view magic);
/// True when `magic` starts with PNG's 8-byte signature.
bool is_png_magic(std::string_view magic);

/// Display and data windows of an EXR header, size-checked.
struct ExrWindows {
  int width = 0, height = 0;          ///< Display window size: the image we return.
  int display_x0 = 0, display_y0 = 0;  ///< Display window origin in file coordinates.
  int data_x0 = 0, data_y0 = 0, data_x1 = 0, data_y1 = 0;  ///< Data window, inclusive bounds.
};
/// Reads and checks the windows (both within the size limits), throwing InputError naming `path`.
ExrWindows exr_windows(const Imf::Header& header, const std::filesystem::path& path);

/// One channel to read: 4-byte samples (FLOAT or UINT; OpenEXR converts from the stored type) into
/// `out`, a display-window-sized row-major buffer the caller has filled with the value for pixels
/// outside the data window.
struct ExrChannelTarget {
  std::string name;
  Imf::PixelType type = Imf::FLOAT;
  void* out = nullptr;
};

/// Reads the channels (all present in the file) in one pass over the data window and copies the
/// part inside the display window into the targets. Throws what OpenEXR throws; callers convert.
void read_exr_channels(Imf::InputFile& file, const ExrWindows& windows, std::span<const ExrChannelTarget> targets);

/// Writes a scanline EXR atomically (write_file_atomically): `header` and `frame` describe the
/// channels, whose data must cover the header's data window. Library failures become SystemError
/// of one line naming `path`; the errors of write_file_atomically pass through.
void write_exr_atomically(const std::filesystem::path& path, const Imf::Header& header, const Imf::FrameBuffer& frame);

/// OpenEXR's message `message` about the file `path` in ao's words: the problems OpenEXR reports
/// most (a file cut short, a damaged header or offset table, missing attributes) as one phrase
/// each; anything else as OpenEXR's text on one line, without the file name it repeats (the
/// message already starts with it).
std::string exr_words(std::string_view message, const std::filesystem::path& path);

/// Runs `body`, turning OpenEXR's exceptions (Iex, derived from std::exception) into InputError
/// "<path>: <what>: <exr_words>" on one line. InputError and SystemError pass unchanged.
template <class Body>
auto with_exr_errors(const std::filesystem::path& path, std::string_view what, Body&& body) -> decltype(body()) {
  try {
    return body();
  } catch (const InputError&) {
    throw;
  } catch (const SystemError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw SystemError(path.string() + ": out of memory while reading");
  } catch (const std::exception& e) {
    throw InputError(path.string() + ": " + std::string(what) + ": " + exr_words(e.what(), path));
  }
}

}  // namespace ao::io_detail
