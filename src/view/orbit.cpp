// SPDX-License-Identifier: Apache-2.0
#include "view/orbit.h"

#include <algorithm>
#include <cmath>

namespace ao::view {

namespace {

// Pitch stays this far from straight up or down, where yaw loses its meaning and the look-at
// basis its up vector.
constexpr float kMaxPitch = 0.5f * kPi - 0.01f;

// Coordinates of v in the orbit's frame: (a, b) in the horizontal plane, h along the up axis.
struct Horizontal {
  float a, b, h;
};
Horizontal split(Vec3 v, UpAxis axis) { return axis == UpAxis::Y ? Horizontal{v.x, v.z, v.y} : Horizontal{v.x, -v.y, v.z}; }
Vec3 join(float a, float b, float h, UpAxis axis) { return axis == UpAxis::Y ? Vec3{a, h, b} : Vec3{a, -b, h}; }

}  // namespace

OrbitCamera::OrbitCamera(const Camera& start) : target_(start.target), fov_deg_(start.vertical_fov_deg) {
  up_axis_ = std::abs(start.up.z) > std::abs(start.up.y) ? UpAxis::Z : UpAxis::Y;
  const Vec3 offset = start.eye - start.target;  // from the target to the eye
  distance_ = std::max(length(offset), 1e-6f);
  const Horizontal s = split(offset / distance_, up_axis_);
  yaw_ = std::atan2(s.a, s.b);
  pitch_ = std::clamp(std::asin(std::clamp(s.h, -1.0f, 1.0f)), -kMaxPitch, kMaxPitch);
}

Vec3 OrbitCamera::up() const { return up_axis_ == UpAxis::Y ? Vec3{0, 1, 0} : Vec3{0, 0, 1}; }

Vec3 OrbitCamera::forward_direction() const {
  const float c = std::cos(pitch_);
  return -join(c * std::sin(yaw_), c * std::cos(yaw_), std::sin(pitch_), up_axis_);
}

void OrbitCamera::orbit(float dx, float dy, int window_height) {
  const float per_pixel = kPi / static_cast<float>(std::max(window_height, 1));
  yaw_ -= dx * per_pixel;
  pitch_ = std::clamp(pitch_ + dy * per_pixel, -kMaxPitch, kMaxPitch);
}

void OrbitCamera::pan(float dx, float dy, int window_height) {
  const Camera cam = camera(1, 1);
  const Frame basis = cam.basis();
  // One pixel at the target's depth spans 2 d tan(fov/2) / height world units.
  const float per_pixel = 2.0f * distance_ * cam.tan_half_fov() / static_cast<float>(std::max(window_height, 1));
  target_ = target_ - basis.t * (dx * per_pixel) + basis.b * (dy * per_pixel);
}

void OrbitCamera::zoom(float steps) { distance_ = std::max(distance_ * std::pow(0.85f, steps), 1e-6f); }

void OrbitCamera::frame(const Bounds3& bounds, int width, int height) {
  const Camera framed = frame_bounds(bounds, -forward_direction(), fov_deg_, width, height);
  target_ = framed.target;
  distance_ = std::max(length(framed.eye - framed.target), 1e-6f);
}

void OrbitCamera::set_up_axis(UpAxis axis) {
  if (axis == up_axis_) return;
  const Vec3 offset = -forward_direction();
  up_axis_ = axis;
  const Horizontal s = split(offset, up_axis_);
  yaw_ = std::atan2(s.a, s.b);
  pitch_ = std::clamp(std::asin(std::clamp(s.h, -1.0f, 1.0f)), -kMaxPitch, kMaxPitch);
}

Camera OrbitCamera::camera(int width, int height) const {
  Camera c;
  c.target = target_;
  c.eye = target_ - forward_direction() * distance_;
  c.up = up();
  c.vertical_fov_deg = fov_deg_;
  c.width = width;
  c.height = height;
  return c;
}

}  // namespace ao::view
