// SPDX-License-Identifier: Apache-2.0
// The scale-free ray offset (reference/ray_offset.h) and the choice of normal: no
// self-intersection at large coordinates or tiny sizes, no bias against a much smaller offset,
// and the same V about geometric and shading normals where they agree.
#include "ao/reference/ray_offset.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <utility>

#include "ao/gbuffer/render_gbuffer.h"
#include "ao/io/mesh_io.h"
#include "ao/reference/direct_light.h"
#include "ao/reference/raytraced.h"
#include "ao/reference/tangent_sphere.h"
#include "ao/reference/transfer_reference.h"
#include "ao/scene/procedural.h"
#include "support/scenes.h"

namespace ao {
namespace {

Camera looking_at(Vec3 eye, Vec3 target, int w, int h, float fov = 40.0f) {
  Camera c;
  c.eye = eye;
  c.target = target;
  c.vertical_fov_deg = fov;
  c.width = w;
  c.height = h;
  return c;
}

// Every covered pixel of an unoccluded surface has V = 1 exactly: a ray that hits the surface it
// starts on is occluded, so a single self-intersection shows as V < 1.
void expect_open_everywhere(const RayScene& rs, const GBuffer& g, float radius, const char* what) {
  const auto img = render_raytraced(rs, g, {Membership::Step, radius}, {.samples = 64}, 11);
  std::size_t covered = 0, acne = 0;
  for (std::size_t i = 0; i < img.visibility.size(); ++i) {
    if (!g.covered(i)) continue;
    ++covered;
    acne += img.visibility[i] < 1.0f;
  }
  EXPECT_GT(covered, g.object_id.size() / 10) << what;
  EXPECT_EQ(acne, 0u) << what << ": pixels whose rays hit the surface they start on";
}

// A 200 x 200 plane tilted about two axes, centred at (1e4, 2e4, -1.5e4): coordinates where the
// float spacing is 2e-3, so a fixed offset from a unit-scale scene would start rays inside it.
TEST(RayOffset, NoAcneOnTiltedPlaneFarFromOrigin) {
  const Vec3 c{1.0e4f, 2.0e4f, -1.5e4f};
  const Vec3 u = normalize(Vec3{1.0f, 0.3f, 0.2f}), n = normalize(cross(u, Vec3{0.1f, 0.2f, 1.0f}));
  const Vec3 v = cross(n, u);
  const float h = 100.0f;
  const Scene s = test::scene_of({make_quad(c - u * h - v * h, c + u * h - v * h, c + u * h + v * h, c - u * h + v * h)});
  const RayScene rs(s);
  const Vec3 side = dot(n, Vec3{0, 0, 1}) > 0 ? n : -n;
  const GBuffer g = render_gbuffer(rs, looking_at(c + side * 150.0f + u * 40.0f, c, 96, 64));
  expect_open_everywhere(rs, g, 50.0f, "tilted plane at 1e4");
  // The sun pass starts its shadow rays the same way: a sun on the visible side lights every pixel.
  const Image<Vec3> ld = render_direct_light(rs, g, Sun{normalize(side + u * 0.3f), kPi});
  for (std::size_t i = 0; i < ld.size(); ++i)
    if (g.covered(i)) {
      ASSERT_GT(ld[i].x, 0.0f) << "pixel " << i << " shadowed by its own plane";
    }
}

// A convex mesh (a UV sphere's polyhedron) 1e-4 across seen from outside: about the geometric
// normal no direction can hit it again, so V = 1 at every pixel, near the origin and away from it.
TEST(RayOffset, NoAcneOnTinyMesh) {
  for (const Vec3 centre : {Vec3{0, 0, 0}, Vec3{0.3f, -0.2f, 0.1f}}) {
    const float r = 5e-5f;
    const Scene s = test::scene_of({make_sphere(centre, r, 24, 12)});
    const RayScene rs(s);
    const GBuffer g = render_gbuffer(rs, looking_at(centre + Vec3{0.7f, 0.5f, 1.0f} * (4 * r), centre, 96, 64, 30.0f),
                                     GBufferOptions{.normal = SurfaceNormal::Geometric});
    expect_open_everywhere(rs, g, 1e-3f, centre.x == 0 ? "tiny mesh at the origin" : "tiny mesh at (0.3, -0.2, 0.1)");
  }
}

// A flat-shaded cube (each face has its own vertices and normal) on a floor: its shading and
// geometric normals are the same vectors, so both choices give the same image.
TEST(RayOffset, GeometricAndShadingNormalsAgreeOnFlatShadedCube) {
  const Scene s = test::scene_of({make_quad({-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, {-4, 0, -4}), make_box({-0.5f, 0, -0.5f}, {0.5f, 1, 0.5f}, {0.8f, 0.8f, 0.8f}, 20.0f)});
  const RayScene rs(s);
  const Camera cam = looking_at({2.0f, 2.2f, 3.0f}, {0, 0.4f, 0}, 80, 60);
  const GBuffer shading = render_gbuffer(rs, cam, GBufferOptions{.normal = SurfaceNormal::Shading});
  const GBuffer geometric = render_gbuffer(rs, cam, GBufferOptions{.normal = SurfaceNormal::Geometric});
  const Falloff f{Membership::Step, 0.8f};
  const auto a = render_raytraced(rs, shading, f, {.samples = 256}, 5);
  const auto b = render_raytraced(rs, geometric, f, {.samples = 256}, 5);
  double max_diff = 0, sum_v = 0;
  std::size_t covered = 0;
  for (std::size_t i = 0; i < a.visibility.size(); ++i) {
    if (!shading.covered(i)) continue;
    ++covered;
    sum_v += a.visibility[i];
    // Same sample sets; the normals differ by float rounding at most, which can flip a ray that
    // grazes an edge: allow one ray in 256 (1/256 < 0.004).
    max_diff = std::max(max_diff, static_cast<double>(std::abs(a.visibility[i] - b.visibility[i])));
  }
  EXPECT_GT(covered, 1000u);
  EXPECT_LT(sum_v / static_cast<double>(covered), 0.99) << "the scene must have occlusion for the test to mean anything";
  EXPECT_LE(max_diff, 0.004);
}

// A bumpy sphere (radial ripples, so it has creases at many scales) on a ground plane 2000 times
// its size. Returns the mean V over the sphere's pixels and the standard error of that mean.
struct MeanV {
  double mean = 0, std_error = 0;
};
MeanV mean_v_of_object(const RayScene& rs, const GBuffer& g, std::uint32_t object, const Falloff& f, float offset, std::uint32_t seed) {
  const auto img = render_raytraced(rs, g, f, {.samples = 64, .offset = offset}, seed);
  double sum = 0, var = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < img.visibility.size(); ++i) {
    if (!g.covered(i) || g.object_id[i] != object) continue;
    sum += img.visibility[i];
    var += static_cast<double>(img.std_error[i]) * img.std_error[i];
    ++n;
  }
  return {sum / static_cast<double>(n), std::sqrt(var) / static_cast<double>(n)};
}

Mesh bumpy_sphere(Vec3 centre, float radius) {
  Mesh m = make_sphere(centre, radius, 160, 80);
  for (Vec3& p : m.positions) {
    const Vec3 d = normalize(p - centre);
    const float bump = 0.08f * std::sin(9 * d.x) * std::sin(11 * d.y) * std::sin(7 * d.z) + 0.03f * std::sin(31 * d.x + 17 * d.z);
    p = centre + d * (radius * (1 + bump));
  }
  m.normals.clear();  // validate_and_prepare generates smooth normals of the new shape
  return m;
}

// The offset must not bias V: the mean V of the object's pixels with the default offset agrees,
// within 2 standard errors of the difference, with an estimate from an offset 8 times smaller
// (independent seeds; 8 float spacings is still clear of the rounding, see NoAcne* above). The old rule, 1e-5 x the scene diagonal, fails this here because the
// ground plane makes the diagonal large: the check has the power to see an offset bias.
void expect_unbiased(const Scene& s, std::uint32_t object, float object_diagonal, const char* what) {
  const RayScene rs(s);
  const Bounds3 ob = s.meshes[object - 1].bounds();
  const Vec3 c = ob.center();
  const GBuffer g = render_gbuffer(rs, looking_at(c + Vec3{0.55f, 0.45f, 1.0f} * (1.3f * object_diagonal), c, 320, 240));
  const Falloff f{Membership::Step, 0.1f * object_diagonal};
  const MeanV ours = mean_v_of_object(rs, g, object, f, 0.0f, 1);
  // 8 float spacings of the largest coordinate a ray origin involves here (the eye's plus the
  // camera-space point's), instead of kRayOffsetUlps = 64.
  const float eye_scale = max_abs_coordinate(g.camera.eye) + object_diagonal;
  const MeanV tiny = mean_v_of_object(rs, g, object, f, ray_offset_distance(eye_scale) * (8.0f / kRayOffsetUlps), 2);
  const double se = std::sqrt(ours.std_error * ours.std_error + tiny.std_error * tiny.std_error);
  EXPECT_LE(std::abs(ours.mean - tiny.mean), 2 * se) << what << ": default " << ours.mean << ", tiny offset " << tiny.mean;
  const MeanV old_rule = mean_v_of_object(rs, g, object, f, 1e-5f * s.bounds().diagonal(), 3);
  EXPECT_GT(old_rule.mean - tiny.mean, 2 * se) << what << ": the old offset should be visibly biased with a large ground";
}

Mesh ground_under(const Bounds3& b, float scale) {
  const Vec3 c = b.center();
  const float e = scale * b.diagonal();
  return make_quad({c.x - e, b.lo.y, c.z + e}, {c.x + e, b.lo.y, c.z + e}, {c.x + e, b.lo.y, c.z - e}, {c.x - e, b.lo.y, c.z - e});
}

TEST(RayOffset, UnbiasedOnBumpyMeshWithLargeGround) {
  Mesh m = bumpy_sphere({0.2f, 1.0f, -0.3f}, 1.0f);
  const Bounds3 b = m.bounds();
  const Scene s = test::scene_of({std::move(m), ground_under(b, 1000.0f)});
  expect_unbiased(s, 1, b.diagonal(), "bumpy sphere");
}

TEST(RayOffset, UnbiasedOnScannedMeshesWithLargeGround) {
  const std::filesystem::path dir(AO_TEST_MESHES);
  for (const char* name : {"elephant.off", "ChineseDragon-10kv.off"}) {
    Scene s = load_scene_file(dir / name);
    const Bounds3 b = s.bounds();
    s.meshes.resize(1);
    s.meshes.push_back(ground_under(b, 1000.0f));
    validate_and_prepare(s);
    expect_unbiased(s, 1, b.diagonal(), name);
  }
}

// Every ray-traced reference starts its rays as raytraced.cpp does (gbuffer_rays_internal.h: per
// triangle, along the geometric normal). A concave crease 1 cm across at the origin, and a quad
// out of view at 1e4: an offset from the scene's magnitude (64 float spacings of 1e4, 7.6 cm)
// would start every ray beyond R = 5 mm from the crease, so V = 1 everywhere; the per-triangle
// offset (64 spacings of 1e-2) agrees with an offset 8 times smaller within 2 standard errors.
TEST(RayOffset, ReferencesOffsetPerTriangleNotByTheScene) {
  const float c = 0.01f;
  const Scene s = test::scene_of({make_quad({0, 0, c}, {c, 0, c}, {c, 0, 0}, {0, 0, 0}), make_quad({0, 0, 0}, {c, 0, 0}, {c, c, 0}, {0, c, 0}),
                                  make_quad({1e4f, 0, 1e4f}, {1e4f + 1, 0, 1e4f}, {1e4f + 1, 1, 1e4f}, {1e4f, 1, 1e4f})});
  const RayScene rs(s);
  const GBuffer g = render_gbuffer(rs, looking_at({0.7f * c, 0.6f * c, 1.4f * c}, {0.4f * c, 0.2f * c, 0.3f * c}, 64, 48, 50.0f));
  const float radius = 0.5f * c;
  const float tiny = ray_offset_distance(max_abs_coordinate(g.camera.eye) + c) * (8.0f / kRayOffsetUlps);
  const float scene_rule = ray_offset_distance(bounds_magnitude(s.bounds()));
  // Mean of V over covered pixels and its standard error, for each reference and offset.
  const auto mean_of = [&](const RaytracedImage& img) {
    double sum = 0, var = 0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < img.visibility.size(); ++i) {
      if (!g.covered(i)) continue;
      sum += img.visibility[i];
      var += static_cast<double>(img.std_error[i]) * img.std_error[i];
      ++n;
    }
    EXPECT_GT(n, 500u);
    return MeanV{sum / static_cast<double>(n), std::sqrt(var) / static_cast<double>(n)};
  };
  const auto tangent = [&](float offset, std::uint32_t seed) {
    return mean_of(render_tangent_sphere(rs, g, radius, {.samples = 64, .offset = offset}, seed));
  };
  const auto transfer = [&](float offset, std::uint32_t seed) {
    return mean_of(render_transfer_reference(rs, g, {Membership::Step, radius}, 0.0f, {.samples = 64, .offset = offset}, seed).scalar);
  };
  for (const auto& [name, run] : {std::pair<const char*, std::function<MeanV(float, std::uint32_t)>>{"tangent sphere", tangent},
                                  {"transfer", transfer}}) {
    const MeanV ours = run(0.0f, 1), small = run(tiny, 2), old_rule = run(scene_rule, 3);
    const double se = std::sqrt(ours.std_error * ours.std_error + small.std_error * small.std_error);
    EXPECT_LT(small.mean, 0.99) << name << ": the crease must occlude for the test to mean anything";
    EXPECT_LE(std::abs(ours.mean - small.mean), 2 * se) << name << ": default " << ours.mean << ", tiny offset " << small.mean;
    EXPECT_GT(old_rule.mean - small.mean, 2 * se) << name << ": the scene-magnitude offset should be visibly biased here";
  }
}

TEST(RayOffset, OffsetFollowsTheCoordinatesNotTheScene) {
  EXPECT_FLOAT_EQ(ray_offset_distance(1.0f), kRayOffsetUlps * 0x1p-23f);
  EXPECT_FLOAT_EQ(ray_offset_distance(1e4f) / ray_offset_distance(1e-4f), 1e8f);
  const Vec3 p = offset_ray_origin({1, 2, 3}, {0, 0, 1}, 3.0f);
  EXPECT_GT(p.z, 3.0f);
  EXPECT_EQ(p.x, 1.0f);
}

}  // namespace
}  // namespace ao
