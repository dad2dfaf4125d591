// SPDX-License-Identifier: Apache-2.0
// Per-vertex AO PLY (ply_export.h): parsed back here with a reader of our own (independent of the
// writer and of assimp), then loaded with load_scene_file to check that a real PLY reader takes it.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <sstream>

#include "ao/core/error.h"
#include "ao/io/mesh_io.h"
#include "ao/io/ply_export.h"
#include "ao/scene/procedural.h"
#include "support/run.h"

namespace ao {
namespace {

struct PlyVertex {
  float x, y, z, nx, ny, nz;
  std::uint8_t r, g, b;
  float quality;
};

struct ParsedPly {
  std::vector<std::string> header;  // lines up to and including end_header
  std::vector<PlyVertex> vertices;
  std::vector<std::array<std::int32_t, 3>> faces;
  std::size_t trailing_bytes = 0;
};

template <class T>
T take(const std::string& s, std::size_t& at) {
  T v;
  if (at + sizeof(T) > s.size()) throw std::runtime_error("truncated PLY body");
  std::memcpy(&v, s.data() + at, sizeof(T));
  at += sizeof(T);
  return v;
}

// Reads exactly the layout the header announces; the property list is checked by the caller.
ParsedPly parse_ply(const std::string& bytes) {
  ParsedPly p;
  std::size_t at = 0;
  std::size_t nv = 0, nf = 0;
  while (true) {
    const std::size_t eol = bytes.find('\n', at);
    if (eol == std::string::npos) throw std::runtime_error("no end_header");
    const std::string line = bytes.substr(at, eol - at);
    at = eol + 1;
    p.header.push_back(line);
    std::istringstream ls(line);
    std::string a, b;
    ls >> a >> b;
    if (a == "element" && b == "vertex") ls >> nv;
    if (a == "element" && b == "face") ls >> nf;
    if (line == "end_header") break;
  }
  for (std::size_t i = 0; i < nv; ++i) {
    PlyVertex v;
    v.x = take<float>(bytes, at), v.y = take<float>(bytes, at), v.z = take<float>(bytes, at);
    v.nx = take<float>(bytes, at), v.ny = take<float>(bytes, at), v.nz = take<float>(bytes, at);
    v.r = take<std::uint8_t>(bytes, at), v.g = take<std::uint8_t>(bytes, at), v.b = take<std::uint8_t>(bytes, at);
    v.quality = take<float>(bytes, at);
    p.vertices.push_back(v);
  }
  for (std::size_t i = 0; i < nf; ++i) {
    const auto count = take<std::uint8_t>(bytes, at);
    if (count != 3) throw std::runtime_error("face with " + std::to_string(count) + " vertices");
    std::array<std::int32_t, 3> f{};
    for (auto& k : f) k = take<std::int32_t>(bytes, at);
    p.faces.push_back(f);
  }
  p.trailing_bytes = bytes.size() - at;
  return p;
}

// Two meshes (a quad and a box), so the writer's merging and index offsets are exercised.
Scene two_meshes() {
  Scene s;
  s.name = "two";
  s.meshes.push_back(make_quad({-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}));
  s.meshes.push_back(make_box({-0.5f, 0.2f, -0.5f}, {0.5f, 1.2f, 0.5f}));
  validate_and_prepare(s);
  return s;
}

std::vector<float> test_values(std::size_t n) {
  std::vector<float> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<float>(i % 11) / 10.0f;  // 0, 0.1, ..., 1.0
  return v;
}

TEST(PlyExport, BinaryLayoutCountsAndValuesReadBack) {
  test::TempDir dir;
  const Scene s = two_meshes();
  std::vector<float> values = test_values(s.vertex_count());
  values[1] = 1.5f;   // out of range: colour clamps to 255, quality keeps the value
  values[2] = -0.25f; // colour clamps to 0
  const auto path = dir / "ao.ply";
  write_vertex_ao_ply(path, s, values);
  const ParsedPly p = parse_ply(test::read_text(path));

  ASSERT_GE(p.header.size(), 3u);
  EXPECT_EQ(p.header[0], "ply");
  EXPECT_EQ(p.header[1], "format binary_little_endian 1.0");
  // The properties MeshLab and Blender look for, in the order the body uses.
  std::vector<std::string> props;
  for (const std::string& l : p.header)
    if (l.rfind("property", 0) == 0) props.push_back(l);
  const std::vector<std::string> expected = {"property float x",      "property float y",     "property float z",    "property float nx",
                                             "property float ny",     "property float nz",    "property uchar red",  "property uchar green",
                                             "property uchar blue",   "property float quality", "property list uchar int vertex_indices"};
  EXPECT_EQ(props, expected);

  ASSERT_EQ(p.vertices.size(), s.vertex_count());
  ASSERT_EQ(p.faces.size(), s.triangle_count());
  EXPECT_EQ(p.trailing_bytes, 0u);

  std::size_t vi = 0, fi = 0, base = 0;
  for (const Mesh& m : s.meshes) {
    for (std::size_t v = 0; v < m.positions.size(); ++v, ++vi) {
      const PlyVertex& pv = p.vertices[vi];
      EXPECT_EQ(pv.x, m.positions[v].x);
      EXPECT_EQ(pv.y, m.positions[v].y);
      EXPECT_EQ(pv.z, m.positions[v].z);
      EXPECT_EQ(pv.nx, m.normals[v].x);
      EXPECT_EQ(pv.ny, m.normals[v].y);
      EXPECT_EQ(pv.nz, m.normals[v].z);
      EXPECT_EQ(pv.quality, values[vi]) << vi;
      const float c = std::clamp(values[vi], 0.0f, 1.0f);
      EXPECT_EQ(pv.r, static_cast<int>(std::lround(c * 255))) << vi;
      EXPECT_EQ(pv.g, pv.r);
      EXPECT_EQ(pv.b, pv.r);
    }
    for (std::size_t t = 0; t < m.triangle_count(); ++t, ++fi)
      for (int k = 0; k < 3; ++k) EXPECT_EQ(p.faces[fi][k], static_cast<std::int32_t>(base + m.indices[3 * t + k])) << "face " << fi;
    base += m.positions.size();
  }
  EXPECT_EQ(p.vertices[1].r, 255);
  EXPECT_EQ(p.vertices[2].r, 0);
  EXPECT_EQ(p.vertices[2].quality, -0.25f);
}

TEST(PlyExport, AssimpLoadsTheFileWithTheSameMesh) {
  test::TempDir dir;
  const Scene s = two_meshes();
  const auto path = dir / "ao.ply";
  write_vertex_ao_ply(path, s, test_values(s.vertex_count()));
  const Scene back = load_scene_file(path);
  EXPECT_EQ(back.triangle_count(), s.triangle_count());
  // Positions survive (as a set: a reader may reorder or weld vertices).
  ASSERT_FALSE(back.meshes.empty());
  const Bounds3 a = s.bounds(), b = back.bounds();
  EXPECT_EQ(a.lo, b.lo);
  EXPECT_EQ(a.hi, b.hi);
}

TEST(PlyExport, WrongValueCountIsAnErrorAndWritesNothing) {
  test::TempDir dir;
  const Scene s = two_meshes();
  const auto path = dir / "ao.ply";
  EXPECT_THROW(write_vertex_ao_ply(path, s, std::vector<float>(s.vertex_count() - 1, 0.5f)), InputError);
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace ao
