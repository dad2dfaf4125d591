// SPDX-License-Identifier: Apache-2.0
#include "ao/io/exr_common_internal.h"

#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStdIO.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <vector>

#include "ao/core/error.h"
#include "ao/io/atomic_file.h"

namespace ao::io_detail {

namespace fs = std::filesystem;

namespace {

/// OpenEXR's details (what follows the file name in its messages), as ao says them.
struct ExrWords {
  std::string_view needle, words;
};
constexpr ExrWords kExrWords[] = {
    {"Early end of file", "truncated: the file ends before its data does"},
    {"Unexpected data block", "damaged pixel data: a block lies at the wrong place"},
    {"decompression", "damaged pixel data: a block does not decompress"},
    {"Missing or empty channel list", "its header lists no channels"},
    {"Unexpected type for image attribute", "damaged header: an attribute has the wrong type"},
    {"Invalid size field", "damaged header: an attribute's size is wrong"},
    {"unrecognized flags", "damaged header: unknown format flags"},
    {"Invalid line order", "damaged header: unknown line order"},
    {"not a multiple of the", "damaged header: the data window does not fit the channels' subsampling"},
    {"Cannot read scan line offsets", "damaged offset table"},
    {"Invalid data window", "damaged header: invalid data window"},
    {"Invalid display window", "damaged header: invalid display window"},
    {"Invalid compression", "damaged header: unknown compression"},
    {"does not appear to be an OpenEXR file", "not an OpenEXR file"},
    {"magic number", "not an OpenEXR file"},
    {"No space left", "the disk is full"},
    {"File too large", "the file size limit (ulimit -f) is reached"},
};

}  // namespace

std::string exr_words(std::string_view message, const fs::path& path) {
  for (const ExrWords& w : kExrWords)
    if (message.find(w.needle) != std::string_view::npos) return std::string(w.words);
  // OpenEXR's messages name the file ("Cannot read image file \"g.exr\". <detail>"); ours already
  // start with it. Without a known detail: what part of the file failed, in general words.
  if (message.find("pixel data") != std::string_view::npos || message.find("tile") != std::string_view::npos)
    return "damaged pixel data";
  if (message.find("Cannot read") != std::string_view::npos || message.find("header") != std::string_view::npos) return "damaged header";
  std::string text(message);
  // Appended piecewise: "literal" + std::string trips GCC 12's false -Wrestrict here.
  std::string quoted(1, '"');
  quoted += path.string();
  quoted += '"';
  for (std::size_t at; (at = text.find(quoted)) != std::string::npos;) text.erase(at, quoted.size());
  return one_line(text);
}

void require_input_file(const fs::path& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw InputError(path.string() + ": file does not exist");
  if (fs::is_directory(status)) throw InputError(path.string() + ": is a directory, not a file");
  if (!fs::is_regular_file(status)) throw InputError(path.string() + ": not a regular file");
  const auto size = fs::file_size(path, ec);
  if (ec) throw InputError(path.string() + ": cannot read: " + ec.message());
  if (size == 0) throw InputError(path.string() + ": file is empty");
}

void check_image_size(const fs::path& path, std::int64_t width, std::int64_t height, std::string_view what) {
  if (width < 1 || height < 1)
    throw InputError(path.string() + ": " + std::string(what) + " is empty (" + std::to_string(width) + "x" +
                     std::to_string(height) + ")");
  if (width > kMaxImageSide || height > kMaxImageSide || width * height > kMaxImagePixels)
    throw InputError(path.string() + ": " + std::string(what) + " of " + std::to_string(width) + "x" +
                     std::to_string(height) + " pixels exceeds the limit of " + std::to_string(kMaxImageSide) +
                     " per side and 2^28 pixels");
}

std::string read_magic(const fs::path& path, std::size_t count) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open for reading");
  std::string bytes(count, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(count));
  bytes.resize(static_cast<std::size_t>(in.gcount()));
  return bytes;
}

bool is_exr_magic(std::string_view magic) { return magic.size() >= 4 && magic.substr(0, 4) == std::string_view("\x76\x2f\x31\x01", 4); }

bool is_png_magic(std::string_view magic) {
  return magic.size() >= 8 && magic.substr(0, 8) == std::string_view("\x89PNG\r\n\x1a\n", 8);
}

ExrWindows exr_windows(const Imf::Header& header, const fs::path& path) {
  const Imath::Box2i& display = header.displayWindow();
  const Imath::Box2i& data = header.dataWindow();
  // 64-bit arithmetic: a hostile header can hold bounds whose difference overflows int.
  const auto extent = [](int lo, int hi) { return std::int64_t{hi} - std::int64_t{lo} + 1; };
  check_image_size(path, extent(display.min.x, display.max.x), extent(display.min.y, display.max.y), "display window");
  check_image_size(path, extent(data.min.x, data.max.x), extent(data.min.y, data.max.y), "data window");
  ExrWindows w;
  w.width = display.max.x - display.min.x + 1;
  w.height = display.max.y - display.min.y + 1;
  w.display_x0 = display.min.x;
  w.display_y0 = display.min.y;
  w.data_x0 = data.min.x;
  w.data_y0 = data.min.y;
  w.data_x1 = data.max.x;
  w.data_y1 = data.max.y;
  return w;
}

void read_exr_channels(Imf::InputFile& file, const ExrWindows& w, std::span<const ExrChannelTarget> targets) {
  constexpr std::size_t kSample = 4;  // FLOAT and UINT are both 4 bytes
  const std::size_t data_w = static_cast<std::size_t>(w.data_x1 - w.data_x0 + 1);
  const std::size_t data_h = static_cast<std::size_t>(w.data_y1 - w.data_y0 + 1);
  const Imath::Box2i data_box({w.data_x0, w.data_y0}, {w.data_x1, w.data_y1});

  // Read the data window into buffers of its own size, then copy the overlap with the display
  // window: the two may be offset or differ in size (compositors crop to the bounding box).
  std::vector<std::vector<unsigned char>> buffers(targets.size());
  Imf::FrameBuffer frame;
  for (std::size_t i = 0; i < targets.size(); ++i) {
    buffers[i].assign(data_w * data_h * kSample, 0);
    frame.insert(targets[i].name, Imf::Slice::Make(targets[i].type, buffers[i].data(), data_box, kSample, kSample * data_w));
  }
  file.setFrameBuffer(frame);
  file.readPixels(w.data_y0, w.data_y1);

  const int x0 = std::max(w.data_x0, w.display_x0);
  const int x1 = std::min(w.data_x1, w.display_x0 + w.width - 1);
  const int y0 = std::max(w.data_y0, w.display_y0);
  const int y1 = std::min(w.data_y1, w.display_y0 + w.height - 1);
  if (x0 > x1 || y0 > y1) return;  // no overlap: everything stays at the caller's fill value
  const std::size_t row_bytes = static_cast<std::size_t>(x1 - x0 + 1) * kSample;
  for (std::size_t i = 0; i < targets.size(); ++i) {
    auto* out = static_cast<unsigned char*>(targets[i].out);
    for (int y = y0; y <= y1; ++y) {
      const std::size_t src = (static_cast<std::size_t>(y - w.data_y0) * data_w + static_cast<std::size_t>(x0 - w.data_x0)) * kSample;
      const std::size_t dst = (static_cast<std::size_t>(y - w.display_y0) * static_cast<std::size_t>(w.width) +
                               static_cast<std::size_t>(x0 - w.display_x0)) * kSample;
      std::memcpy(out + dst, buffers[i].data() + src, row_bytes);
    }
  }
}

namespace {

/// OpenEXR's output stream over a stdio file (the temporary file open_temporary opened). Write
/// errors are remembered rather than thrown: close_temporary reports them in ao's words.
class StdioOStream : public Imf::OStream {
 public:
  StdioOStream(std::FILE* file, const char* name) : Imf::OStream(name), file_(file) {}
  void write(const char c[], int n) override { std::fwrite(c, 1, static_cast<std::size_t>(n), file_); }
  std::uint64_t tellp() override { return static_cast<std::uint64_t>(::ftello(file_)); }
  void seekp(std::uint64_t pos) override { ::fseeko(file_, static_cast<off_t>(pos), SEEK_SET); }

 private:
  std::FILE* file_;
};

}  // namespace

void write_exr_atomically(const fs::path& path, const Imf::Header& header, const Imf::FrameBuffer& frame) {
  write_file_atomically(path, [&](const fs::path& temp) {
    // Our own stream rather than a file name: OutputFile's destructor writes the line-offset
    // table and swallows any error, so only the file's state after closing tells us whether the
    // whole file reached the disk (a full disk, a file size limit show up there).
    std::FILE* file = open_temporary(temp, path);
    try {
      StdioOStream stream(file, path.c_str());  // the name OpenEXR's messages give: the user's, not the temporary one
      Imf::OutputFile out(stream, header);
      out.setFrameBuffer(frame);
      const Imath::Box2i& data = header.dataWindow();
      out.writePixels(data.max.y - data.min.y + 1);
    } catch (const std::exception& e) {
      std::fclose(file);
      throw SystemError(path.string() + ": cannot write OpenEXR file: " + exr_words(e.what(), path));
    }
    close_temporary(file, path);
  });
}

}  // namespace ao::io_detail
