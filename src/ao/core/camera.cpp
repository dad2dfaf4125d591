// SPDX-License-Identifier: Apache-2.0
#include "ao/core/camera.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <string>

#include "ao/core/error.h"

namespace ao {

namespace {
std::string format_vec(Vec3 v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%g,%g,%g", static_cast<double>(v.x), static_cast<double>(v.y), static_cast<double>(v.z));
  return buf;
}

static_assert(kMaxCameraCoordinate == 1e11f, "Camera::validate's message names the limit");

}

void Camera::validate() const {
  if (!is_finite(eye) || !is_finite(target) || !is_finite(up)) throw InputError("camera: eye, target and up must be finite");
  // The target first: the CLI places an eye for a given target, which then shares its magnitude.
  for (const auto& [name, p] : {std::pair{"--target", target}, std::pair{"--eye", eye}})
    if (std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}) > kMaxCameraCoordinate)
      throw InputError(std::string("camera: ") + name + " " + format_vec(p) + " is beyond +-1e11 world units, the largest camera position ao traces correctly");
  if (length(target - eye) <= 0) throw InputError("camera: eye and target are the same point");
  if (length(cross(normalize(target - eye), normalize(up))) < 1e-4f) throw InputError("camera: up is parallel to the view direction");
  if (!(vertical_fov_deg > 0.0f && vertical_fov_deg < 180.0f))
    throw InputError("camera: --fov must be in (0, 180) degrees, got " + std::to_string(vertical_fov_deg));
  if (width < 1 || height < 1 || width > kMaxImageSide || height > kMaxImageSide)
    throw InputError("camera: resolution " + std::to_string(width) + "x" + std::to_string(height) + " is outside 1.." +
                     std::to_string(kMaxImageSide) + " per side");
}

Frame Camera::basis() const {
  const Vec3 z = normalize(eye - target);
  const Vec3 x = normalize(cross(up, z));
  const Vec3 y = cross(z, x);
  return {x, y, z};
}

float Camera::tan_half_fov() const { return std::tan(vertical_fov_deg * kPi / 360.0f); }

Vec3 Camera::camera_direction(float px, float py) const {
  const float t = tan_half_fov();
  const float sx = (2.0f * px / static_cast<float>(width) - 1.0f) * t * aspect();
  const float sy = (1.0f - 2.0f * py / static_cast<float>(height)) * t;
  return {sx, sy, -1.0f};
}

Vec2 Camera::project(Vec3 p) const {
  const float t = tan_half_fov();
  const float sx = p.x / (-p.z) / (t * aspect());
  const float sy = p.y / (-p.z) / t;
  return {(sx + 1.0f) * 0.5f * static_cast<float>(width), (1.0f - sy) * 0.5f * static_cast<float>(height)};
}

Vec3 Camera::world_to_camera_point(Vec3 p) const { return basis().to_local(p - eye); }
Vec3 Camera::camera_to_world_point(Vec3 p) const { return basis().to_world(p) + eye; }
Vec3 Camera::world_to_camera_vector(Vec3 v) const { return basis().to_local(v); }
Vec3 Camera::camera_to_world_vector(Vec3 v) const { return basis().to_world(v); }

Camera frame_bounds(const Bounds3& bounds, Vec3 direction, float vertical_fov_deg, int width, int height) {
  Camera c;
  c.vertical_fov_deg = vertical_fov_deg;
  c.width = width;
  c.height = height;
  const Vec3 dir = normalize(direction);
  c.target = bounds.center();
  c.up = std::abs(dir.y) > 0.999f ? Vec3{0, 0, -1} : Vec3{0, 1, 0};
  c.eye = c.target + dir;  // provisional, for the basis
  const Frame basis = c.basis();
  const float tan_v = c.tan_half_fov(), tan_h = tan_v * c.aspect();
  // The distance from the centre at which every corner of the box projects inside the image:
  // a corner at (x, y, z) in the camera basis (z towards the camera) is at depth distance - z, and
  // fits when |x| <= tan_h (distance - z) and |y| <= tan_v (distance - z).
  float distance = 1e-6f;
  for (int i = 0; i < 8; ++i) {
    const Vec3 corner{i & 1 ? bounds.hi.x : bounds.lo.x, i & 2 ? bounds.hi.y : bounds.lo.y, i & 4 ? bounds.hi.z : bounds.lo.z};
    const Vec3 p = basis.to_local(corner - c.target);
    distance = std::max({distance, p.z + std::abs(p.x) / tan_h, p.z + std::abs(p.y) / tan_v});
  }
  c.eye = c.target + dir * (1.08f * distance);  // a small margin around the tightest fit
  return c;
}

}  // namespace ao
