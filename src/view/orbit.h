// SPDX-License-Identifier: Apache-2.0
// The viewer's camera: an orbit about a target point, in the terms people drag with (yaw and pitch
// about the up axis, a distance, a pan of the target), turned into the library's look-at Camera.
// Pure math, no window: `ao view` drives it from mouse and key events, the tests drive it directly.
#pragma once

#include "ao/core/camera.h"
#include "ao/core/math.h"

namespace ao::view {

/// Which world axis points up: the built-in scenes and most game assets are y-up, CAD and scanned
/// data are often z-up.
enum class UpAxis { Y, Z };

class OrbitCamera {
 public:
  OrbitCamera() = default;
  /// Starts at `start` (as ao render would frame it): its target, distance and direction are kept,
  /// its up vector chooses the up axis (z-up when it is closer to +z than to +y).
  explicit OrbitCamera(const Camera& start);

  /// Turns about the target: `dx`, `dy` in pixels of mouse motion; a drag across the window's
  /// height turns by about 180 degrees. Pitch stops short of the poles.
  void orbit(float dx, float dy, int window_height);
  /// Moves the target (and the eye with it) in the image plane, so the point under the cursor
  /// follows the cursor at the target's depth.
  void pan(float dx, float dy, int window_height);
  /// Scroll: each step brings the eye 15% closer to (steps > 0) or farther from the target.
  void zoom(float steps);
  /// Looks at `bounds` from the current direction at the distance where they fill a view of
  /// width x height pixels.
  void frame(const Bounds3& bounds, int width, int height);
  /// Switches the up axis, keeping the eye's position relative to the target as far as possible.
  void set_up_axis(UpAxis axis);

  UpAxis up_axis() const { return up_axis_; }
  float fov_deg() const { return fov_deg_; }
  void set_fov_deg(float fov) { fov_deg_ = fov; }
  /// The look-at camera of width x height pixels.
  Camera camera(int width, int height) const;

 private:
  Vec3 up() const;
  Vec3 forward_direction() const;  ///< From the eye towards the target, unit.

  Vec3 target_{0, 0, 0};
  float distance_ = 5.0f;
  float yaw_ = 0.0f;    ///< Radians about the up axis.
  float pitch_ = 0.0f;  ///< Radians above the horizontal plane, in (-pi/2, pi/2).
  float fov_deg_ = 40.0f;
  UpAxis up_axis_ = UpAxis::Y;
};

}  // namespace ao::view
