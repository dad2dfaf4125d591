// SPDX-License-Identifier: Apache-2.0
// The PLY reader: every encoding and property type gives the same mesh, what it does not use is
// skipped, what ply_export writes reads back exactly, and damaged files are refused naming the
// element and the problem.
#include "ao/io/ply_reader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "ao/core/error.h"
#include "ao/io/mesh_io.h"
#include "ao/io/ply_export.h"
#include "ao/scene/procedural.h"
#include "support/run.h"

namespace ao {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

std::string read_error(const std::string& name, const std::string& data) {
  try {
    read_ply(name, data);
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(name + ": ", 0), 0u) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    return msg;
  }
  ADD_FAILURE() << name << " was read, expected an InputError";
  return {};
}

#define EXPECT_READ_ERROR(data, fragment)                                                                \
  do {                                                                                                   \
    const std::string msg_ = read_error("t.ply", data);                                                  \
    EXPECT_NE(msg_.find(fragment), std::string::npos) << "expected '" << (fragment) << "' in: " << msg_; \
  } while (0)

/// Appends `value` as `T` in the given byte order.
template <class T>
void put(std::string& out, double value, bool big_endian = false) {
  const T v = static_cast<T>(value);
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (big_endian)
    for (std::size_t k = 0; k < sizeof(T) / 2; ++k) std::swap(b[k], b[sizeof(T) - 1 - k]);
  out.append(b, sizeof(T));
}

// A unit square (0,0,0) (1,0,0) (1,1,0) (0,1,0) as one quad face, with normals +z and UVs = xy.
const std::vector<float> kSquare = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};

void expect_square(const Scene& s) {
  ASSERT_EQ(s.meshes.size(), 1u);
  const Mesh& m = s.meshes[0];
  ASSERT_EQ(m.positions.size(), 4u);
  for (std::size_t v = 0; v < 4; ++v) {
    EXPECT_EQ(m.positions[v].x, kSquare[3 * v]);
    EXPECT_EQ(m.positions[v].y, kSquare[3 * v + 1]);
    EXPECT_EQ(m.positions[v].z, kSquare[3 * v + 2]);
  }
  // The quad 0 1 2 3 is fanned from its first corner, keeping its winding.
  EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
}

std::string binary_square(bool big_endian) {
  std::string out = std::string("ply\nformat binary_") + (big_endian ? "big" : "little") +
                    "_endian 1.0\nelement vertex 4\nproperty double x\nproperty float y\nproperty short z\nproperty uchar red\n"
                    "element face 1\nproperty list ushort uint vertex_indices\nproperty int flags\n"
                    "element edge 1\nproperty list uchar int corners\nend_header\n";
  for (int v = 0; v < 4; ++v) {
    put<double>(out, kSquare[3 * v], big_endian);
    put<float>(out, kSquare[3 * v + 1], big_endian);
    put<std::int16_t>(out, kSquare[3 * v + 2], big_endian);
    put<std::uint8_t>(out, 200);
  }
  put<std::uint16_t>(out, 4, big_endian);
  for (int i : {0, 1, 2, 3}) put<std::uint32_t>(out, i, big_endian);
  put<std::int32_t>(out, -7, big_endian);
  put<std::uint8_t>(out, 2);
  put<std::int32_t>(out, 0, big_endian);
  put<std::int32_t>(out, 1, big_endian);
  return out;
}

TEST(PlyReader, BinaryLittleAndBigEndianGiveTheSameMeshSkippingWhatIsNotUsed) {
  expect_square(read_ply("le.ply", binary_square(false)));
  expect_square(read_ply("be.ply", binary_square(true)));
}

TEST(PlyReader, AsciiReadsNormalsAndUvsUnderTheirCommonNames) {
  for (const auto& [u, v] : {std::pair{"u", "v"}, std::pair{"s", "t"}, std::pair{"texture_u", "texture_v"}}) {
    SCOPED_TRACE(u);
    const std::string header = std::string("ply\nformat ascii 1.0\ncomment square\nelement vertex 4\nproperty float x\nproperty float y\n") +
                               "property float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float " + u +
                               "\nproperty float " + v + "\nelement face 1\nproperty list uchar int vertex_index\nend_header\n";
    const Scene s = read_ply("a.ply", header + "0 0 0 0 0 1 0 0\n1 0 0 0 0 1 1 0\n\n1 1 0 0 0 1 1 1\n0 1 0 0 0 1 0 1\n4 0 1 2 3\n");
    expect_square(s);
    ASSERT_EQ(s.meshes[0].normals.size(), 4u);
    ASSERT_EQ(s.meshes[0].uvs.size(), 4u);
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(s.meshes[0].normals[k].z, 1.0f);
      EXPECT_EQ(s.meshes[0].uvs[k].x, kSquare[3 * k]);
      EXPECT_EQ(s.meshes[0].uvs[k].y, kSquare[3 * k + 1]);
    }
  }
}

TEST(PlyReader, WhatPlyExportWritesReadsBackExactly) {
  TempDir dir;
  Scene s;
  s.name = "sphere";
  s.meshes.push_back(make_sphere({0.5f, 1, -2}, 0.75f, 24, 12));
  validate_and_prepare(s);
  const fs::path file = dir / "sphere.ply";
  write_vertex_ao_ply(file, s, std::vector<float>(s.vertex_count(), 0.5f));
  const Scene back = load_scene_file(file);
  ASSERT_EQ(back.meshes.size(), 1u);
  EXPECT_EQ(back.meshes[0].indices, s.meshes[0].indices);
  ASSERT_EQ(back.meshes[0].positions.size(), s.meshes[0].positions.size());
  for (std::size_t v = 0; v < s.meshes[0].positions.size(); ++v) {
    EXPECT_EQ(back.meshes[0].positions[v].x, s.meshes[0].positions[v].x);
    EXPECT_EQ(back.meshes[0].positions[v].y, s.meshes[0].positions[v].y);
    EXPECT_EQ(back.meshes[0].positions[v].z, s.meshes[0].positions[v].z);
    EXPECT_NEAR(back.meshes[0].normals[v].y, s.meshes[0].normals[v].y, 1e-6f);
  }
}

const std::string kHeader3 =
    "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

TEST(PlyReader, DamagedFilesAreRefusedNamingTheProblem) {
  const std::string ascii = "ply\nformat ascii 1.0\n" + kHeader3;
  EXPECT_READ_ERROR(ascii + "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", "face 0 uses vertex 7, the file has 3");
  EXPECT_READ_ERROR(ascii + "0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n", "face 0 uses vertex -1");
  EXPECT_READ_ERROR(ascii + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n", "face 0 has 2 vertices, at least 3 are needed");
  EXPECT_READ_ERROR(ascii + "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n", "'zero' is not a number");
  EXPECT_READ_ERROR(ascii + "0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n", "is not an integer");
  EXPECT_READ_ERROR(ascii + "0 0 0\n1 0\n0 1 0\n3 0 1 2\n", "data line 2");
  EXPECT_READ_ERROR("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nelement face 1\n"
                    "property list uchar int vertex_indices\nend_header\n0 0\n1 0\n0 1\n3 0 1 2\n",
                    "'vertex' element has no 'z' property");
  EXPECT_READ_ERROR("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n",
                    "no 'face' element");
  EXPECT_READ_ERROR("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
                    "property list uchar float vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                    "floating point");
  EXPECT_READ_ERROR("ply\nformat binary_middle_endian 1.0\n" + kHeader3, "no valid format line");
  // A negative list count in a signed binary count type.
  std::string bin = "ply\nformat binary_little_endian 1.0\n" + std::string(kHeader3).replace(kHeader3.find("uchar"), 5, "int");
  for (float c : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) put<float>(bin, c);
  put<std::int32_t>(bin, -3);
  bin += std::string(12, '\0');
  EXPECT_READ_ERROR(bin, "'face' 0 has a negative list count -3");
}

// A grid of n x n quads as triangles: (n + 1)^2 vertices, 2 n^2 faces, in a binary little-endian
// file with the common face layout (uchar count, int indices) that is read in parallel, and in
// ASCII, which is read by the general path.
struct GridPly {
  std::string binary, ascii;
  std::vector<std::uint32_t> indices;
  long long vertices = 0;
};
GridPly grid_ply(int n) {
  GridPly g;
  g.vertices = static_cast<long long>(n + 1) * (n + 1);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const auto at = [n](int i, int j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
      g.indices.insert(g.indices.end(), {at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y), at(x + 1, y + 1), at(x, y + 1)});
    }
  const std::string header = "element vertex " + std::to_string(g.vertices) + "\nproperty float x\nproperty float y\nproperty float z\n" +
                             "element face " + std::to_string(g.indices.size() / 3) + "\nproperty list uchar int vertex_indices\nend_header\n";
  g.binary = "ply\nformat binary_little_endian 1.0\n" + header;
  g.ascii = "ply\nformat ascii 1.0\n" + header;
  for (long long v = 0; v < g.vertices; ++v) {
    const float c[3] = {static_cast<float>(v % (n + 1)) * 0.25f, static_cast<float>(v / (n + 1)) * 0.5f, static_cast<float>(v % 7)};
    for (float f : c) put<float>(g.binary, f);
    for (float f : c) {
      g.ascii += std::to_string(f);
      g.ascii += ' ';
    }
    g.ascii += '\n';
  }
  for (std::size_t t = 0; t < g.indices.size(); t += 3) {
    put<std::uint8_t>(g.binary, 3);
    g.ascii += "3";
    for (int k = 0; k < 3; ++k) {
      put<std::int32_t>(g.binary, g.indices[t + k]);
      g.ascii += ' ';
      g.ascii += std::to_string(g.indices[t + k]);
    }
    g.ascii += "\n";
  }
  return g;
}

/// Byte offset of face f's record in grid_ply(n).binary (13 bytes a face after 12 a vertex).
std::size_t face_offset(const GridPly& g, std::size_t f) { return g.binary.size() - (g.indices.size() / 3 - f) * 13; }

TEST(PlyReader, BinaryTrianglesReadInParallelEqualTheAsciiFile) {
  const GridPly g = grid_ply(150);  // 45,000 faces: several parallel blocks
  const Scene bin = read_ply("grid.ply", g.binary), asc = read_ply("grid.ply", g.ascii);
  EXPECT_EQ(bin.meshes[0].indices, g.indices);
  EXPECT_EQ(asc.meshes[0].indices, g.indices);
  ASSERT_EQ(bin.meshes[0].positions.size(), asc.meshes[0].positions.size());
  for (std::size_t v = 0; v < bin.meshes[0].positions.size(); ++v) {
    EXPECT_EQ(bin.meshes[0].positions[v].x, asc.meshes[0].positions[v].x);
    EXPECT_EQ(bin.meshes[0].positions[v].z, asc.meshes[0].positions[v].z);
  }
}

TEST(PlyReader, BinaryFacesOtherThanTrianglesAndBadIndicesTakeTheGeneralPath) {
  GridPly g = grid_ply(150);
  // The last face a quad: one byte more, which the fast path detects and leaves to the general one.
  std::string quad = g.binary.substr(0, face_offset(g, g.indices.size() / 3 - 1));
  put<std::uint8_t>(quad, 4);
  for (int i : {0, 1, 152, 151}) put<std::int32_t>(quad, i);
  const Scene s = read_ply("quad.ply", quad);
  const std::vector<std::uint32_t>& got = s.meshes[0].indices;
  ASSERT_EQ(got.size(), g.indices.size() + 3);
  EXPECT_TRUE(std::equal(g.indices.begin(), g.indices.end() - 3, got.begin()));
  EXPECT_EQ(std::vector<std::uint32_t>(got.end() - 6, got.end()), (std::vector<std::uint32_t>{0, 1, 152, 0, 152, 151}));
  // Out-of-range indices in two blocks: the first in file order is named, negative ones too.
  std::string bad = g.binary;
  const std::int32_t big = 22801, negative = -1;
  std::memcpy(&bad[face_offset(g, 40000) + 5], &big, 4);
  std::memcpy(&bad[face_offset(g, 33000) + 9], &negative, 4);
  EXPECT_READ_ERROR(bad, "face 33000 uses vertex -1, the file has 22801");
  std::memcpy(&bad[face_offset(g, 33000) + 9], &big, 4);
  EXPECT_READ_ERROR(bad, "face 33000 uses vertex 22801, the file has 22801");
}

TEST(PlyReader, CountsAreCheckedAgainstTheFileBeforeAllocating) {
  // 5e9 faces fail on the header; a million empty binary faces (one zero count byte each, which
  // the size check lets through) fail on the first face.
  EXPECT_READ_ERROR("ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 5000000000\nproperty list uchar int vertex_indices\nend_header\n",
                    "absurd element count");
  std::string many = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                     "element face 1000000\nproperty list uchar int vertex_indices\nend_header\n";
  many += std::string(36 + 1000000, '\0');
  EXPECT_READ_ERROR(many, "face 0 has 0 vertices");
}

// Issue 41: a header declaring one face fewer than the data holds dropped the last face with exit
// 0 (OFF already refused it). Data after the last declared element, other than blank space, is
// refused in every encoding; a trailing line end is not data.
TEST(PlyReader, DataBeyondTheDeclaredElementsIsRefused) {
  const std::string ascii_body = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n";
  const auto ascii = [&](int faces) {
    return "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face " + std::to_string(faces) +
           "\nproperty list uchar int vertex_indices\nend_header\n" + ascii_body;
  };
  EXPECT_EQ(read_ply("t.ply", ascii(2)).meshes[0].triangle_count(), 2u);
  EXPECT_EQ(read_ply("t.ply", ascii(2) + "\n \n").meshes[0].triangle_count(), 2u);
  EXPECT_READ_ERROR(ascii(1), "the header declares 4 x 'vertex', 1 x 'face' elements, but the data holds more after the last of them");
  // Binary: the square's face list, then one more face the header does not declare.
  std::string binary = binary_square(false);
  EXPECT_NO_THROW(read_ply("t.ply", binary + "\n"));
  put<std::uint8_t>(binary, 3);
  for (int i : {0, 1, 2}) put<std::int32_t>(binary, i);
  EXPECT_READ_ERROR(binary, "but the data holds more after the last of them (13 more bytes)");
}

// Issue 41: a header with a 100 KB comment line was "no end_header line" (only the first 64 KiB
// were searched). Lines are read whole, and "end_header" inside a comment ends nothing.
TEST(PlyReader, LongCommentsAreReadAndEndHeaderInsideOneEndsNothing) {
  const std::string body = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                           "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const std::string long_comment = "comment " + std::string(100000, 'x') + " end_header\n";
  const Scene s = read_ply("t.ply", "ply\n" + long_comment + body.substr(4));
  EXPECT_EQ(s.meshes[0].triangle_count(), 1u);
  EXPECT_EQ(read_ply("t.ply", "ply\ncomment see end_header below\n" + body.substr(4)).meshes[0].triangle_count(), 1u);
}

}  // namespace
}  // namespace ao
