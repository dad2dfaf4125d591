// SPDX-License-Identifier: Apache-2.0
// UV coverage (bake/texel_coverage.h) held to its definition: every triangle clipped against every
// texel square its UV box touches, one texel at a time, the fragments of a texel in triangle order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "ao/bake/texel_coverage.h"
#include "ao/scene/mesh.h"

namespace ao {
namespace {

// A deterministic stream of floats in [0, 1) (a 32-bit LCG's top 24 bits).
struct Lcg {
  std::uint32_t state;
  float next() {
    state = state * 1664525u + 1013904223u;
    return static_cast<float>(state >> 8) * 0x1.0p-24f;
  }
};

// `count` separate triangles of random shapes: most a few texels of a 37 x 23 map across, some
// spanning many texels, some reaching outside [0, 1]^2; world positions a random affine image of
// the UVs, so no triangle is degenerate.
Mesh random_uv_triangles(std::uint32_t seed, int count) {
  Lcg r{seed};
  Mesh m;
  for (int t = 0; t < count; ++t) {
    const float size = t % 50 == 0 ? 0.6f : (t % 7 == 0 ? 0.15f : 0.06f);
    const float cu = r.next() * 1.2f - 0.1f, cv = r.next() * 1.2f - 0.1f;
    for (int c = 0; c < 3; ++c) {
      const Vec2 uv{cu + (r.next() - 0.5f) * size, cv + (r.next() - 0.5f) * size};
      m.uvs.push_back(uv);
      m.positions.push_back({uv.x * 2.0f + uv.y * 0.3f, uv.y * 1.5f, uv.x * 0.7f - uv.y + r.next() * 0.01f});
      m.indices.push_back(static_cast<std::uint32_t>(m.positions.size() - 1));
    }
  }
  return m;
}

// The fragments of compute_texel_coverage(s, width, height), asked for a texel at a time
// (texel_fragments) and a bin at a time (bin_fragments), their areas (to the bit: the same clips)
// and each texel's sums must be what clipping one texel at a time, triangle after triangle, gives.
void expect_texel_by_texel_clips(const Scene& s, int width, int height) {
  const TexelCoverage cov = compute_texel_coverage(s, width, height);
  struct Expected {
    std::uint32_t mesh, triangle;
    float uv_area;
  };
  std::vector<std::vector<Expected>> per_texel(static_cast<std::size_t>(width) * height);
  for (std::uint32_t mi = 0; mi < s.meshes.size(); ++mi) {
    const Mesh& m = s.meshes[mi];
    for (std::uint32_t t = 0; t < m.triangle_count(); ++t) {
      const std::uint32_t* i = &m.indices[3 * static_cast<std::size_t>(t)];
      const Vec2 a = texel_uv(m, i[0], width, height), b = texel_uv(m, i[1], width, height), c = texel_uv(m, i[2], width, height);
      const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a.x, b.x, c.x})))), x1 = std::min(width - 1, static_cast<int>(std::floor(std::max({a.x, b.x, c.x}))));
      const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a.y, b.y, c.y})))), y1 = std::min(height - 1, static_cast<int>(std::floor(std::max({a.y, b.y, c.y}))));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const float area = clip_to_texel(a, b, c, x, y).area();
          if (area > 0) per_texel[static_cast<std::size_t>(y) * width + x].push_back({mi, t, area});
        }
    }
  }
  ASSERT_EQ(cov.degenerate_uv_triangles, 0u);
  EXPECT_GT(cov.outside_triangles, 0u);
  std::size_t fragments = 0, covered = 0;
  std::vector<TexelPiece> got;
  BinFragments bin;
  for (std::size_t texel = 0; texel < per_texel.size(); ++texel) {
    const std::vector<Expected>& want = per_texel[texel];
    // A texel's fragments asked for alone, and with the rest of its bin.
    texel_fragments(s, cov, texel, got);
    const int x = static_cast<int>(texel % width), y = static_cast<int>(texel / width), b = TexelCoverage::kBin;
    bin_fragments(s, cov, x / b, y / b, bin);
    const std::span<const TexelPiece> of_bin = bin.texel((y % b) * b + x % b);
    ASSERT_EQ(got.size(), want.size()) << "texel " << texel;
    ASSERT_EQ(of_bin.size(), want.size()) << "texel " << texel;
    float uv_sum = 0;
    for (std::size_t k = 0; k < want.size(); ++k) {
      for (const TexelFragment& f : {got[k].fragment, of_bin[k].fragment}) {
        EXPECT_EQ(f.mesh, want[k].mesh) << "texel " << texel << " fragment " << k;
        EXPECT_EQ(f.triangle, want[k].triangle) << "texel " << texel << " fragment " << k;
        EXPECT_EQ(f.uv_area, want[k].uv_area) << "texel " << texel << " fragment " << k;
      }
      EXPECT_EQ(got[k].polygon.area(), want[k].uv_area) << "texel " << texel << " fragment " << k;
      EXPECT_EQ(of_bin[k].polygon.n, got[k].polygon.n) << "texel " << texel << " fragment " << k;
      uv_sum += want[k].uv_area;
    }
    EXPECT_EQ(cov.uv_area[texel], uv_sum) << "texel " << texel;  // summed in fragment order
    EXPECT_EQ(cov.mask[texel], want.empty() ? 0 : 1) << "texel " << texel;
    fragments += want.size();
    covered += !want.empty();
  }
  EXPECT_EQ(cov.fragments, fragments);
  EXPECT_EQ(cov.covered_texels, covered);
  EXPECT_GT(fragments, 5000u);  // most triangles reach several texels
}

// Two meshes: a texel's fragments run in mesh, then triangle order.
Scene two_random_meshes() {
  Scene s;
  s.name = "random";
  s.meshes.push_back(random_uv_triangles(7, 5000));
  s.meshes.push_back(random_uv_triangles(11, 300));
  validate_and_prepare(s);
  return s;
}

TEST(TexelCoverage, FragmentsAreTheTexelByTexelClipsInTriangleOrder) {
  // A map whose sides are not a whole number of bins (8 texels).
  expect_texel_by_texel_clips(two_random_meshes(), 37, 23);
}

TEST(TexelCoverage, FragmentsDoNotDependOnHowTheBinsRunInParallel) {
  // Many rows of bins, summed on every thread there is, several times: a texel's sums must not
  // depend on which thread ran its bin, nor on the bins beside it.
  const Scene s = two_random_meshes();
  for (int round = 0; round < 8; ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    expect_texel_by_texel_clips(s, 29, 301);
    if (HasFailure()) return;
  }
}

TEST(TexelCoverage, ClipOfATriangleInsideATexelIsTheTriangle) {
  // No line of the texel cuts the triangle: its corners come back as they were, area exact.
  const ClipPolygon p = clip_to_texel({3.25f, 5.5f}, {3.75f, 5.25f}, {3.5f, 5.75f}, 3, 5);
  ASSERT_EQ(p.n, 3);
  EXPECT_EQ(p.p[0].x, 3.25f);
  EXPECT_EQ(p.p[1].y, 5.25f);
  EXPECT_EQ(p.p[2].x, 3.5f);
  EXPECT_FLOAT_EQ(p.area(), 0.09375f);  // half of |(0.5, -0.25) x (0.25, 0.25)|
  // A triangle covering the texel with room to spare: the unit square.
  const ClipPolygon q = clip_to_texel({-10, -10}, {30, -10}, {-10, 30}, 2, 4);
  EXPECT_EQ(q.n, 4);
  EXPECT_EQ(q.area(), 1.0f);
  // A triangle wholly in another texel: nothing.
  EXPECT_EQ(clip_to_texel({3.25f, 5.5f}, {3.75f, 5.25f}, {3.5f, 5.75f}, 4, 5).n, 0);
}

}  // namespace
}  // namespace ao
