// SPDX-License-Identifier: Apache-2.0
// Shared by the screen-space method tests: small G-buffers of built-in and hand-made scenes, and
// one-pixel G-buffers for the analytic (implicit-surface) cases.
#pragma once

#include <utility>

#include "ao/eval/metrics.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/reference/raytraced.h"
#include "ao/scene/procedural.h"

namespace ao::test {

inline constexpr int kWidth = 160, kHeight = 120;

struct SceneGBuffer {
  Scene scene;
  std::unique_ptr<RayScene> rays;
  GBuffer g;
};

/// A scene's G-buffer at kWidth x kHeight from its preferred view (or `view`).
inline SceneGBuffer scene_gbuffer(Scene s, std::optional<Camera> view = std::nullopt) {
  SceneGBuffer out{std::move(s), nullptr, {}};
  out.rays = std::make_unique<RayScene>(out.scene);
  Camera c = view ? *view : *out.scene.preferred_view;
  c.width = kWidth;
  c.height = kHeight;
  out.g = render_gbuffer(*out.rays, c);
  return out;
}

inline SceneGBuffer builtin_gbuffer(const char* name) { return scene_gbuffer(make_builtin_scene(name)); }

/// A 1 x 1 G-buffer whose only pixel holds camera-space point p with normal n (for implicit and
/// height-field characteristic functions, which do not read the depth buffer).
inline GBuffer one_pixel(Vec3 p, Vec3 n, Vec3 albedo = {0.5f, 0.5f, 0.5f}) {
  Camera c;
  c.width = c.height = 1;
  GBuffer g(c);
  g.position(0, 0) = p;
  g.normal(0, 0) = normalize(n);
  g.albedo(0, 0) = albedo;
  g.object_id(0, 0) = 1;
  return g;
}

/// RMSE of `v` against the ray-traced reference over covered pixels.
inline double rmse_against(const Image<float>& v, const Image<float>& reference, const GBuffer& g) {
  return compare_images(v, reference, coverage_mask(g)).rmse;
}

}  // namespace ao::test
