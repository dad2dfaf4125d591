// SPDX-License-Identifier: Apache-2.0
// Shared by the GPU backend's tests: one device for the whole test binary (Mesa's software
// renderer, so results do not depend on the machine's GPU; CI has no GPU), and small scenes with
// their CPU G-buffers (the images are small: llvmpipe runs the shaders on the CPU).
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "ao/gbuffer/render_gbuffer.h"
#include "ao/gpu/device.h"
#include "ao/gpu/gbuffer.h"
#include "ao/reference/ray_scene.h"
#include "ao/scene/procedural.h"

namespace ao::test {

/// The test binary's device: llvmpipe through EGL, opened on first use. A machine without a usable
/// GL fails the GPU tests with the device's one-line error (scripts/setup installs Mesa).
inline GpuDevice& gpu_device() {
  static GpuDevice device = GpuDevice::open({.software = true});
  return device;
}

/// A built-in scene, its ray tracer, its GPU copy and its CPU G-buffer from the scene's own view at
/// width x height.
struct GpuFixture {
  Scene scene;
  std::unique_ptr<RayScene> rays;
  std::unique_ptr<GpuScene> gpu_scene;
  GBuffer g;
  float radius = 0;  ///< R: 0.1 x the diagonal of the scene's bounds, as `ao render`'s default order of magnitude.
};

/// Closed meshes only (a box for the ground, a sphere resting on it, a turned box and a torus): what
/// the paper's parity voxelization, the GPU cone's, needs. Seen from the front right and above.
inline Scene closed_scene() {
  Scene s;
  s.name = "closed";
  s.meshes.push_back(make_box({-3.0f, -0.3f, -3.0f}, {3.0f, 0.0f, 3.0f}, {0.7f, 0.7f, 0.7f}));
  s.meshes.push_back(make_sphere({-0.8f, 0.7f, 0.2f}, 0.7f, 48, 24, {0.8f, 0.3f, 0.2f}));
  s.meshes.push_back(make_box({0.4f, 0.0f, -0.9f}, {1.4f, 1.2f, 0.1f}, {0.3f, 0.6f, 0.8f}, 30.0f));
  s.meshes.push_back(make_torus({0.6f, 0.25f, 1.3f}, 0.6f, 0.25f, 48, 16, {0.8f, 0.8f, 0.3f}));
  validate_and_prepare(s);
  Bounds3 objects;  // framed without the ground, which would make them small
  for (std::size_t m = 1; m < s.meshes.size(); ++m) objects.extend(s.meshes[m].bounds());
  s.preferred_view = frame_bounds(objects, {0.6f, 0.7f, 1.0f}, 40.0f, 16, 16);
  return s;
}

/// A torus drawn three times as instances (moved, turned and mirrored, stretched) over a closed
/// floor: the glTF node tree's repeated mesh (docs/instancing.md), each instance an object.
inline Scene instanced_scene() {
  Scene s;
  s.name = "instanced";
  s.meshes.push_back(make_box({-3.0f, -0.3f, -3.0f}, {3.0f, 0.0f, 3.0f}));
  s.meshes.push_back(make_torus({0, 0, 0}, 0.6f, 0.25f, 48, 16, {0.8f, 0.5f, 0.3f}));
  Affine3 moved, turned, stretched;
  moved.c3 = {-1.2f, 0.25f, 0.3f};
  turned.c0 = {0, 0, 1}, turned.c1 = {0, -1, 0}, turned.c2 = {1, 0, 0}, turned.c3 = {0.6f, 0.85f, -0.8f};  // a mirror: det -1
  stretched.c0 = {1.5f, 0, 0}, stretched.c1 = {0, 0.7f, 0.2f}, stretched.c3 = {0.9f, 0.2f, 1.2f};
  s.instances = {{1, moved, "moved"}, {1, turned, "turned"}, {1, stretched, "stretched"}};
  validate_and_prepare(s);
  s.preferred_view = frame_bounds(Bounds3{{-2, 0, -1.5f}, {2, 1.5f, 2}}, {0.6f, 0.7f, 1.0f}, 40.0f, 16, 16);
  return s;
}

/// `name`: a built-in scene, "closed" (closed_scene()) or "instanced" (instanced_scene()).
inline GpuFixture gpu_fixture(const std::string& name, int width = 96, int height = 64) {
  GpuFixture f{name == "closed" ? closed_scene() : name == "instanced" ? instanced_scene() : make_builtin_scene(name), nullptr, nullptr, {}, 0};
  f.rays = std::make_unique<RayScene>(f.scene);
  f.gpu_scene = std::make_unique<GpuScene>(GpuScene::upload(gpu_device(), f.scene));
  Camera c = *f.scene.preferred_view;
  c.width = width;
  c.height = height;
  f.g = render_gbuffer(*f.rays, c);
  f.radius = 0.1f * f.scene.bounds().diagonal();
  return f;
}

/// A test name from a scene name ("sphere-on-plane" -> "sphere_on_plane").
inline std::string scene_test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string n = info.param;
  for (char& ch : n)
    if (ch == '-' || ch == '*') ch = '_';
  return n;
}

}  // namespace ao::test
