// SPDX-License-Identifier: Apache-2.0
// validate_and_prepare and generate_normals on meshes big enough to span several of their parallel
// blocks: the results equal a plain serial loop written here (the definition in mesh.h), do not
// depend on the thread count, and the first offender in file order is the one named.
#include "ao/scene/mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <tbb/global_control.h>

#include "ao/core/error.h"

namespace ao {
namespace {

/// An n x n grid of quads over a bumpy height field, two triangles each: 2 n^2 triangles.
Mesh bumpy_grid(int n) {
  Mesh m;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) {
      const float u = static_cast<float>(x) / n, v = static_cast<float>(y) / n;
      m.positions.push_back({u, v, 0.1f * std::sin(12 * u) * std::cos(9 * v)});
    }
  const auto at = [n](int x, int y) { return static_cast<std::uint32_t>(y * (n + 1) + x); };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) m.indices.insert(m.indices.end(), {at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y), at(x + 1, y + 1), at(x, y + 1)});
  return m;
}

/// The definition: each triangle adds its unit normal, weighted by its angle at the vertex, to
/// its three vertices, in triangle order; sums are normalised.
std::vector<Vec3> serial_normals(const Mesh& m) {
  std::vector<Vec3> sum(m.positions.size());
  for (std::size_t t = 0; t < m.indices.size(); t += 3) {
    const Vec3 p[3] = {m.positions[m.indices[t]], m.positions[m.indices[t + 1]], m.positions[m.indices[t + 2]]};
    const Vec3 n = normalize(cross(p[1] - p[0], p[2] - p[0]));
    for (int k = 0; k < 3; ++k) {
      const float angle = std::acos(std::clamp(dot(normalize(p[(k + 1) % 3] - p[k]), normalize(p[(k + 2) % 3] - p[k])), -1.0f, 1.0f));
      sum[m.indices[t + k]] += n * angle;
    }
  }
  for (Vec3& s : sum) s = length(s) > 0 ? normalize(s) : Vec3{0, 0, 1};
  return sum;
}

std::string error_of(Scene s) {
  try {
    validate_and_prepare(s);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(Mesh, GeneratedNormalsEqualTheSerialDefinitionAtAnyThreadCount) {
  Mesh m = bumpy_grid(200);  // 80,000 triangles: several parallel blocks
  m.positions.push_back({5, 5, 5});  // used by no triangle: +z
  const std::vector<Vec3> want = serial_normals(m);
  generate_normals(m);
  ASSERT_EQ(m.normals.size(), want.size());
  // Same sums in the same order; 1e-6 allows a compiler's different contraction into fused
  // multiply-adds between the two loops (unit vectors, so absolute).
  for (std::size_t v = 0; v < want.size(); ++v) {
    EXPECT_NEAR(m.normals[v].x, want[v].x, 1e-6f) << v;
    EXPECT_NEAR(m.normals[v].y, want[v].y, 1e-6f) << v;
    EXPECT_NEAR(m.normals[v].z, want[v].z, 1e-6f) << v;
  }
  EXPECT_EQ(m.normals.back().z, 1.0f);
  Mesh one = m;
  {
    tbb::global_control serial(tbb::global_control::max_allowed_parallelism, 1);
    generate_normals(one);
  }
  for (std::size_t v = 0; v < want.size(); ++v) {
    EXPECT_EQ(one.normals[v].x, m.normals[v].x);
    EXPECT_EQ(one.normals[v].y, m.normals[v].y);
    EXPECT_EQ(one.normals[v].z, m.normals[v].z);
  }
}

TEST(Mesh, DegenerateTrianglesAreDroppedAcrossBlocksKeepingTheOrder) {
  Scene s;
  s.name = "grid";
  s.meshes.push_back(bumpy_grid(200));
  const std::vector<std::uint32_t> good = s.meshes[0].indices;
  // Two degenerate triangles after every 997th, in every block.
  std::vector<std::uint32_t> mixed;
  std::size_t inserted = 0;
  for (std::size_t t = 0; t < good.size(); t += 3) {
    mixed.insert(mixed.end(), good.begin() + static_cast<long>(t), good.begin() + static_cast<long>(t + 3));
    if ((t / 3) % 997 == 0) {
      mixed.insert(mixed.end(), {good[t], good[t], good[t + 1]});
      mixed.insert(mixed.end(), {good[t + 1], good[t + 2], good[t + 1]});
      inserted += 2;
    }
  }
  s.meshes[0].indices = mixed;
  validate_and_prepare(s);
  EXPECT_EQ(s.meshes[0].indices, good);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("dropped " + std::to_string(inserted) + " degenerate"), std::string::npos) << s.warnings[0];
  EXPECT_GE(s.meshes[0].positions.capacity(), s.meshes[0].positions.size() + kVertexPadding);
}

TEST(Mesh, TheFirstBadVertexAndTriangleInFileOrderAreNamed) {
  Scene s;
  s.name = "grid.ply";
  s.meshes.push_back(bumpy_grid(200));
  Scene far = s;
  far.meshes[0].positions[30000].x = std::numeric_limits<float>::quiet_NaN();
  far.meshes[0].positions[70].y = 2e9f;
  far.meshes[0].positions[9].z = -3e9f;
  EXPECT_EQ(error_of(far), "grid.ply: vertex 9 has coordinate 3e+09, beyond the +-1e+09 ao traces correctly (scale the mesh down)");
  Scene nan = s;
  nan.meshes[0].positions[40000].x = std::numeric_limits<float>::quiet_NaN();
  nan.meshes[0].positions[33000].z = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(error_of(nan), "grid.ply: vertex 33000 has a non-finite coordinate");
  Scene range = s;
  range.meshes[0].indices[3 * 70000 + 1] = 1u << 31;
  range.meshes[0].indices[3 * 50000 + 2] = 40401;  // one past the last of the 201^2 vertices
  EXPECT_EQ(error_of(range), "grid.ply: triangle 50000 uses vertex 40401, the mesh has 40401");
  Scene normals = s;
  normals.meshes[0].normals.assign(normals.meshes[0].positions.size(), Vec3{0, 0, 2});
  normals.meshes[0].normals[39000].y = std::numeric_limits<float>::infinity();
  normals.meshes[0].normals[35000].x = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(error_of(normals), "grid.ply: normal 35000 is not finite");
}

}  // namespace
}  // namespace ao
