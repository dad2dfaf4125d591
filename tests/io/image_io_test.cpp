// SPDX-License-Identifier: Apache-2.0
// Image files and atomic writes: exact EXR round trips, PNG quantisation bounds, RGB handling, and
// families of bad input that must each give one line naming the file.
#include "ao/io/image_io.h"

#include <gtest/gtest.h>
#include <linux/capability.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "ao/core/error.h"
#include "support/errors.h"
#include "support/run.h"
#include "ao/io/atomic_file.h"

namespace ao {
namespace {

namespace fs = std::filesystem;

using test::TempDir;
using test::expect_one_line_error;

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// A smooth ramp with a few exact quantisation levels, in [0,1].
Image<float> ramp(int width, int height) {
  Image<float> image(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) image(x, y) = static_cast<float>(x + y * width) / static_cast<float>(width * height - 1);
  return image;
}

Image<Vec3> colour_ramp(int width, int height) {
  Image<Vec3> image(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      image(x, y) = {static_cast<float>(x) / (width - 1), static_cast<float>(y) / (height - 1), 0.25f + 0.5f * ((x + y) % 2)};
  return image;
}

// --- atomic writes --------------------------------------------------------------------------

TEST(AtomicFile, ReplacesAnExistingFile) {
  TempDir dir;
  const fs::path path = dir / "out.txt";
  write_bytes(path, "old");
  write_file_atomically(path, [](const fs::path& temp) { write_bytes(temp, "new"); });
  EXPECT_EQ(read_bytes(path), "new");
  EXPECT_EQ(dir.file_count(), 1);
}

TEST(AtomicFile, TemporaryFileIsHiddenBesideTheTargetAndKeepsTheExtension) {
  TempDir dir;
  const fs::path path = dir / "ao.exr";
  fs::path seen;
  write_file_atomically(path, [&](const fs::path& temp) {
    seen = temp;
    EXPECT_TRUE(fs::exists(temp));
    write_bytes(temp, "x");
  });
  EXPECT_EQ(seen.parent_path(), path.parent_path());
  EXPECT_EQ(seen.filename().string().front(), '.');
  EXPECT_EQ(seen.extension(), ".exr");
  EXPECT_FALSE(fs::exists(seen));
}

TEST(AtomicFile, WriteThatThrowsHalfWayLeavesTheExistingFileAndNoTemporaryFile) {
  TempDir dir;
  const fs::path path = dir / "out.png";
  write_bytes(path, "precious");
  EXPECT_THROW(write_file_atomically(path,
                                     [](const fs::path& temp) {
                                       write_bytes(temp, "half a fi");
                                       throw std::runtime_error("disk exploded");
                                     }),
               std::runtime_error);
  EXPECT_EQ(read_bytes(path), "precious");
  EXPECT_EQ(dir.file_count(), 1);
}

TEST(AtomicFile, MissingDirectoryIsAnErrorNamingThePath) {
  TempDir dir;
  const fs::path path = dir / "no-such-dir" / "out.exr";
  expect_one_line_error<InputError>([&] { write_file_atomically(path, [](const fs::path&) {}); }, path, "does not exist");
  EXPECT_EQ(dir.file_count(), 0);
}

TEST(AtomicFile, DirectoryAsTargetIsAnError) {
  TempDir dir;
  fs::create_directory(dir / "sub.png");
  expect_one_line_error<InputError>([&] { write_file_atomically(dir / "sub.png", [](const fs::path&) {}); }, dir / "sub.png",
                                    "is a directory");
}

// While alive, the calling thread obeys file permission bits even as root: the capabilities that
// override them (CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH, CAP_FOWNER) are cleared from the thread's
// effective set and restored from its permitted set on destruction. Linux capabilities are per
// thread, and the code under test writes from the calling thread.
class PermissionBitsApply {
 public:
  PermissionBitsApply() {
    header_.version = _LINUX_CAPABILITY_VERSION_3;
    header_.pid = 0;
    if (::syscall(SYS_capget, &header_, saved_) != 0) return;
    __user_cap_data_struct reduced[2] = {saved_[0], saved_[1]};
    for (const int cap : {CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH, CAP_FOWNER})
      reduced[cap / 32].effective &= ~(1u << (cap % 32));
    active_ = ::syscall(SYS_capset, &header_, reduced) == 0;
  }
  ~PermissionBitsApply() {
    if (active_) ::syscall(SYS_capset, &header_, saved_);
  }
  PermissionBitsApply(const PermissionBitsApply&) = delete;
  PermissionBitsApply& operator=(const PermissionBitsApply&) = delete;

 private:
  __user_cap_header_struct header_{};
  __user_cap_data_struct saved_[2]{};
  bool active_ = false;
};

TEST(AtomicFile, UnwritableDirectoryIsASystemErrorNamingThePath) {
  TempDir dir;
  fs::create_directory(dir / "ro");
  fs::permissions(dir / "ro", fs::perms::owner_read | fs::perms::owner_exec);
  {
    const PermissionBitsApply as_an_ordinary_user;
    expect_one_line_error<SystemError>([&] { write_file_atomically(dir / "ro" / "x.png", [](const fs::path&) {}); },
                                       dir / "ro" / "x.png", "cannot create");
  }
  fs::permissions(dir / "ro", fs::perms::owner_all);
}

// --- writing and reading images ---------------------------------------------------------------

TEST(ImageIo, ExrFloatRoundTripIsExactIncludingNonFiniteValues) {
  TempDir dir;
  Image<float> image = ramp(37, 23);
  image(0, 0) = -2.5f;
  image(1, 0) = 1e30f;
  image(2, 0) = std::numeric_limits<float>::infinity();
  image(3, 0) = std::numeric_limits<float>::quiet_NaN();
  image(4, 0) = std::numeric_limits<float>::denorm_min();
  write_image(dir / "v.exr", image);
  const Image<float> back = read_image(dir / "v.exr");
  ASSERT_EQ(back.width(), 37);
  ASSERT_EQ(back.height(), 23);
  for (std::size_t i = 0; i < image.size(); ++i) {
    if (std::isnan(image[i]))
      EXPECT_TRUE(std::isnan(back[i]));
    else
      EXPECT_EQ(back[i], image[i]) << "pixel " << i;
  }
}

TEST(ImageIo, ExrSingleChannelIsNamedYAsFloat) {
  TempDir dir;
  write_image(dir / "v.exr", ramp(4, 4));
  // The header's channel list stores each name, NUL, then the pixel type as int32 (FLOAT = 2).
  const std::string bytes = read_bytes(dir / "v.exr");
  EXPECT_NE(bytes.find(std::string("chlist\0", 7)), std::string::npos);
  EXPECT_NE(bytes.find(std::string("Y\0\x02\0\0\0", 6)), std::string::npos);
}

TEST(ImageIo, ExrChannelNameCanBeChosenAndIsReadBack) {
  TempDir dir;
  ImageWriteOptions opt;
  opt.exr_channel = "visibility";
  write_image(dir / "v.exr", ramp(5, 3), opt);
  EXPECT_NE(read_bytes(dir / "v.exr").find(std::string("visibility\0", 11)), std::string::npos);
  EXPECT_EQ(read_image(dir / "v.exr")(4, 2), 1.0f);  // the only channel is the one read
}

TEST(ImageIo, Png8BitRoundTripIsWithinHalfAStep) {
  TempDir dir;
  const Image<float> image = ramp(64, 33);
  write_image(dir / "v.png", image);
  const Image<float> back = read_image(dir / "v.png");
  ASSERT_EQ(back.width(), 64);
  ASSERT_EQ(back.height(), 33);
  // Rounding to the nearest of 255 steps moves a value by at most half a step.
  for (std::size_t i = 0; i < image.size(); ++i) EXPECT_NEAR(back[i], image[i], 0.5f / 255.0f + 1e-6f);
}

TEST(ImageIo, Png16BitRoundTripIsWithinHalfAStep) {
  TempDir dir;
  const Image<float> image = ramp(300, 7);
  ImageWriteOptions opt;
  opt.png_bits = 16;
  write_image(dir / "v.png", image, opt);
  const Image<float> back = read_image(dir / "v.png");
  for (std::size_t i = 0; i < image.size(); ++i) EXPECT_NEAR(back[i], image[i], 0.5f / 65535.0f + 1e-7f);
}

TEST(ImageIo, PngClampsToUnitRangeAndWritesNanAsZero) {
  TempDir dir;
  Image<float> image(4, 1);
  image(0, 0) = -1.0f;
  image(1, 0) = 2.0f;
  image(2, 0) = std::numeric_limits<float>::quiet_NaN();
  image(3, 0) = std::numeric_limits<float>::infinity();
  write_image(dir / "v.png", image);
  const Image<float> back = read_image(dir / "v.png");
  EXPECT_EQ(back(0, 0), 0.0f);
  EXPECT_EQ(back(1, 0), 1.0f);
  EXPECT_EQ(back(2, 0), 0.0f);
  EXPECT_EQ(back(3, 0), 1.0f);
}

TEST(ImageIo, PngSrgbEncodesOnWriteAndDecodesOnRequest) {
  TempDir dir;
  Image<float> image(2, 1);
  image(0, 0) = 0.2140f;  // sRGB encodes linear 0.214 as 0.5
  image(1, 0) = 0.8f;
  ImageWriteOptions opt;
  opt.srgb = true;
  opt.png_bits = 16;
  write_image(dir / "v.png", image, opt);
  EXPECT_NEAR(read_image(dir / "v.png")(0, 0), 0.5f, 1e-3f);  // stored values as is by default
  ImageReadOptions read_opt;
  read_opt.srgb = true;
  const Image<float> back = read_image(dir / "v.png", read_opt);
  // Half a 16-bit step in the encoded value, times the largest slope of the decoding curve (< 2.3).
  EXPECT_NEAR(back(0, 0), image(0, 0), 2.3f * 0.5f / 65535.0f);
  EXPECT_NEAR(back(1, 0), image(1, 0), 2.3f * 0.5f / 65535.0f);
}

TEST(ImageIo, RgbRoundTripIsExactInExrAndWithinHalfAStepInPng) {
  TempDir dir;
  const Image<Vec3> image = colour_ramp(19, 11);
  write_rgb_image(dir / "c.exr", image);
  write_rgb_image(dir / "c.png", image);
  const Image<Vec3> exr = read_rgb_image(dir / "c.exr");
  const Image<Vec3> png = read_rgb_image(dir / "c.png");
  ASSERT_EQ(exr.width(), 19);
  ASSERT_EQ(png.height(), 11);
  for (std::size_t i = 0; i < image.size(); ++i) {
    EXPECT_EQ(exr[i], image[i]);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(png[i][c], image[i][c], 0.5f / 255.0f + 1e-6f);
  }
}

TEST(ImageIo, SingleChannelReadOfRgbTakesTheRedChannel) {
  TempDir dir;
  const Image<Vec3> image = colour_ramp(9, 5);
  write_rgb_image(dir / "orm.png", image);
  write_rgb_image(dir / "orm.exr", image);
  const Image<float> png = read_image(dir / "orm.png");
  const Image<float> exr = read_image(dir / "orm.exr");
  for (std::size_t i = 0; i < image.size(); ++i) {
    EXPECT_NEAR(png[i], image[i].x, 0.5f / 255.0f + 1e-6f);
    EXPECT_EQ(exr[i], image[i].x);
  }
}

TEST(ImageIo, RgbReadOfGreyRepeatsTheValue) {
  TempDir dir;
  const Image<float> image = ramp(6, 6);
  write_image(dir / "g.exr", image);
  write_image(dir / "g.png", image, {.png_bits = 16});
  const Image<Vec3> exr = read_rgb_image(dir / "g.exr");
  const Image<Vec3> png = read_rgb_image(dir / "g.png");
  for (std::size_t i = 0; i < image.size(); ++i) {
    EXPECT_EQ(exr[i], (Vec3{image[i], image[i], image[i]}));
    EXPECT_EQ(png[i].x, png[i].z);
    EXPECT_NEAR(png[i].y, image[i], 1e-4f);
  }
}

TEST(ImageIo, ExtensionIsCaseInsensitiveAndReadingGoesByContent) {
  TempDir dir;
  write_image(dir / "v.PNG", ramp(3, 3));
  fs::copy_file(dir / "v.PNG", dir / "really-a-png.exr");
  EXPECT_EQ(read_image(dir / "really-a-png.exr")(2, 2), 1.0f);
  EXPECT_TRUE(is_supported_image_path("a/B.Exr"));
  EXPECT_TRUE(is_supported_image_path("a/b.JPG"));
  EXPECT_FALSE(is_supported_image_path("a/b.webp"));
}

TEST(ImageIo, UnknownExtensionIsAnErrorListingTheSupportedOnes) {
  TempDir dir;
  expect_one_line_error<InputError>([&] { write_image(dir / "v.webp", ramp(2, 2)); }, dir / "v.webp", ".exr, .png, .tif");
  expect_one_line_error<InputError>([&] { write_rgb_image(dir / "v", colour_ramp(2, 2)); }, dir / "v", "supported");
  EXPECT_EQ(dir.file_count(), 0);
}

TEST(ImageIo, BadOptionsAndEmptyImagesAreRejected) {
  TempDir dir;
  EXPECT_THROW(write_image(dir / "v.png", ramp(2, 2), {.png_bits = 12}), InputError);
  EXPECT_THROW(write_image(dir / "v.exr", ramp(2, 2), {.exr_channel = ""}), InputError);
  EXPECT_THROW(write_image(dir / "v.jpg", ramp(2, 2), {.jpeg_quality = 0}), InputError);
  EXPECT_THROW(write_image(dir / "v.jpg", ramp(2, 2), {.jpeg_quality = 101}), InputError);
  expect_one_line_error<InputError>([&] { write_image(dir / "v.exr", Image<float>()); }, dir / "v.exr", "empty");
  EXPECT_EQ(dir.file_count(), 0);
}

TEST(ImageIo, WritingIntoAMissingDirectoryNamesThePath) {
  TempDir dir;
  const fs::path path = dir / "missing" / "v.exr";
  expect_one_line_error<InputError>([&] { write_image(path, ramp(2, 2)); }, path, "does not exist");
  expect_one_line_error<InputError>([&] { write_image(dir / "missing" / "v.png", ramp(2, 2)); }, dir / "missing" / "v.png",
                                    "does not exist");
}

TEST(ImageIo, RejectedWriteLeavesTheExistingImage) {
  TempDir dir;
  write_image(dir / "v.png", ramp(4, 4));
  const std::string before = read_bytes(dir / "v.png");
  EXPECT_THROW(write_image(dir / "v.png", ramp(4, 4), {.png_bits = 3}), InputError);
  EXPECT_EQ(read_bytes(dir / "v.png"), before);
  EXPECT_EQ(dir.file_count(), 1);
}

// --- bad input ---------------------------------------------------------------------------------

TEST(ImageIo, MissingFileIsAnError) {
  TempDir dir;
  expect_one_line_error<InputError>([&] { read_image(dir / "nope.exr"); }, dir / "nope.exr", "does not exist");
}

TEST(ImageIo, EmptyFileIsAnError) {
  TempDir dir;
  write_bytes(dir / "empty.png", "");
  expect_one_line_error<InputError>([&] { read_image(dir / "empty.png"); }, dir / "empty.png", "empty");
}

TEST(ImageIo, TruncatedExrIsAnError) {
  TempDir dir;
  write_image(dir / "full.exr", ramp(64, 64));
  const std::string bytes = read_bytes(dir / "full.exr");
  write_bytes(dir / "half.exr", bytes.substr(0, bytes.size() / 2));
  expect_one_line_error<InputError>([&] { read_image(dir / "half.exr"); }, dir / "half.exr", "OpenEXR");
  // Cut inside the header too.
  write_bytes(dir / "head.exr", bytes.substr(0, 40));
  expect_one_line_error<InputError>([&] { read_image(dir / "head.exr"); }, dir / "head.exr", "OpenEXR");
}

TEST(ImageIo, TruncatedPngIsAnError) {
  TempDir dir;
  write_rgb_image(dir / "full.png", colour_ramp(64, 64));
  const std::string bytes = read_bytes(dir / "full.png");
  for (const std::size_t keep : {bytes.size() / 2, std::size_t{12}, bytes.size() - 13}) {
    write_bytes(dir / "cut.png", bytes.substr(0, keep));
    expect_one_line_error<InputError>([&] { read_image(dir / "cut.png"); }, dir / "cut.png", "PNG");
  }
}

TEST(ImageIo, CorruptedPngDataIsAnError) {
  TempDir dir;
  write_image(dir / "full.png", ramp(64, 64));
  std::string bytes = read_bytes(dir / "full.png");
  bytes[bytes.size() / 2] ^= 0x5a;  // breaks the IDAT checksum
  write_bytes(dir / "bad.png", bytes);
  expect_one_line_error<InputError>([&] { read_image(dir / "bad.png"); }, dir / "bad.png", "PNG");
}

TEST(ImageIo, RandomBytesWithExrExtensionAreAnError) {
  TempDir dir;
  std::mt19937 rng(7);
  std::string bytes(4096, '\0');
  for (char& c : bytes) c = static_cast<char>(rng());
  write_bytes(dir / "noise.exr", bytes);
  expect_one_line_error<InputError>([&] { read_image(dir / "noise.exr"); }, dir / "noise.exr", "not an image");
  // Random bytes behind a valid magic number reach the OpenEXR parser itself.
  write_bytes(dir / "magic.exr", std::string("\x76\x2f\x31\x01", 4) + bytes);
  expect_one_line_error<InputError>([&] { read_image(dir / "magic.exr"); }, dir / "magic.exr", "OpenEXR");
}

TEST(ImageIo, TextWithPngExtensionIsAnError) {
  TempDir dir;
  write_bytes(dir / "notes.png", "this is not a picture\n");
  expect_one_line_error<InputError>([&] { read_rgb_image(dir / "notes.png"); }, dir / "notes.png", "not an image");
}

TEST(ImageIo, DirectoryIsNotAnImage) {
  TempDir dir;
  fs::create_directory(dir / "d.png");
  expect_one_line_error<InputError>([&] { read_image(dir / "d.png"); }, dir / "d.png", "directory");
}

// CRC-32 of PNG chunks (ISO 3309), to forge a header that passes libpng's checks.
std::uint32_t crc32(const std::string& bytes) {
  std::uint32_t crc = 0xffffffffu;
  for (const unsigned char b : bytes) {
    crc ^= b;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

void put_be32(std::string& bytes, std::size_t at, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) bytes[at + k] = static_cast<char>((v >> (24 - 8 * k)) & 0xffu);
}

TEST(ImageIo, AbsurdPngSizeIsRejectedBeforeAllocating) {
  TempDir dir;
  write_image(dir / "small.png", ramp(4, 4));
  std::string bytes = read_bytes(dir / "small.png");
  // IHDR follows the 8-byte signature: length(4) "IHDR"(4) width(4) height(4) ... crc.
  for (const auto& [w, h] : {std::pair<std::uint32_t, std::uint32_t>{40000, 4}, {30000, 30000}}) {
    put_be32(bytes, 16, w);
    put_be32(bytes, 20, h);
    put_be32(bytes, 29, crc32(bytes.substr(12, 17)));
    write_bytes(dir / "huge.png", bytes);
    expect_one_line_error<InputError>([&] { read_image(dir / "huge.png"); }, dir / "huge.png", "exceeds the limit");
  }
}

TEST(ImageIo, AbsurdExrSizeIsRejectedBeforeAllocating) {
  TempDir dir;
  write_image(dir / "small.exr", ramp(4, 4));
  std::string bytes = read_bytes(dir / "small.exr");
  // Attributes are stored as name NUL type NUL size(int32) value; a box2i is four int32s
  // (min.x, min.y, max.x, max.y), little-endian.
  for (const std::string name : {"dataWindow", "displayWindow"}) {
    const std::size_t at = bytes.find(name + std::string("\0box2i\0", 7));
    ASSERT_NE(at, std::string::npos);
    const std::size_t max_x = at + name.size() + 7 + 4 + 8;
    for (int k = 0; k < 4; ++k) bytes[max_x + k] = static_cast<char>((1000000 >> (8 * k)) & 0xff);
  }
  write_bytes(dir / "huge.exr", bytes);
  expect_one_line_error<InputError>([&] { read_image(dir / "huge.exr"); }, dir / "huge.exr", "exceeds the limit");
}

}  // namespace
}  // namespace ao
