// SPDX-License-Identifier: Apache-2.0
// Pinhole camera. Camera space is right-handed and looks down -z, with +x right and +y up in
// the image; pixel (0,0) is the top-left corner of the image and pixel centres sit at +0.5.
#pragma once

#include <algorithm>

#include "ao/core/math.h"

namespace ao {

/// Largest coordinate magnitude (world units) of a camera's eye and target: 100 x the scene limit
/// (kMaxCoordinate in scene/mesh.h), room to frame the largest scene from afar. `ao render` of a
/// cube of half-side 1e9 seen from 5e11 away matches the unit cube's image (BENCHMARKS.md,
/// "Input limits").
inline constexpr float kMaxCameraCoordinate = 1e11f;
/// The largest image side, pixels: 32k x 32k float images are 4 GiB, and beyond that is a typo.
inline constexpr int kMaxImageSide = 32768;

struct Camera {
  Vec3 eye{0, 0, 5};                ///< Centre of projection, world units, each |coordinate| <= kMaxCameraCoordinate.
  Vec3 target{0, 0, 0};             ///< Point looked at, world units, as eye; must differ from eye.
  Vec3 up{0, 1, 0};                 ///< Approximate up direction; must not be parallel to target - eye.
  float vertical_fov_deg = 45.0f;   ///< Full vertical field of view, degrees, in (0, 180).
  int width = 1280;                 ///< Image width, pixels, >= 1.
  int height = 720;                 ///< Image height, pixels, >= 1.

  /// Throws InputError naming the bad field (degenerate look-at, fov out of range, absurd size).
  void validate() const;

  /// Orthonormal camera basis in world space: x right, y up, z backwards (camera looks down -z).
  Frame basis() const;
  /// tan(vertical_fov / 2).
  float tan_half_fov() const;
  float aspect() const { return static_cast<float>(width) / static_cast<float>(height); }

  /// Camera-space direction (not normalised, z = -1) through continuous pixel coordinate (px, py).
  Vec3 camera_direction(float px, float py) const;
  /// Continuous pixel coordinate of a camera-space point in front of the camera (p.z < 0).
  Vec2 project(Vec3 p_camera) const;

  Vec3 world_to_camera_point(Vec3 p) const;
  Vec3 camera_to_world_point(Vec3 p) const;
  Vec3 world_to_camera_vector(Vec3 v) const;
  Vec3 camera_to_world_vector(Vec3 v) const;
};

/// Camera that frames the bounds: looks at their centre from `direction` (world, need not be unit)
/// at the distance where the bounding sphere fills the smaller field of view.
Camera frame_bounds(const Bounds3& bounds, Vec3 direction, float vertical_fov_deg, int width, int height);

/// Camera-space point -> pixel index of the G-buffer, with the arithmetic of Camera::project
/// folded into four constants.
struct ScreenProjection {
  float scale_x = 1, scale_y = 1;   ///< Pixels per unit of x/(-z) and y/(-z).
  float centre_x = 0, centre_y = 0; ///< Pixel coordinate of the optical axis.
  int width = 0, height = 0;

  static ScreenProjection from_camera(const Camera& c) {
    const float t = c.tan_half_fov();
    return {0.5f * static_cast<float>(c.width) / (t * c.aspect()), 0.5f * static_cast<float>(c.height) / t,
            0.5f * static_cast<float>(c.width), 0.5f * static_cast<float>(c.height), c.width, c.height};
  }
  /// Sets `index` to y * width + x of the pixel containing p's projection, clamped to the image
  /// (a point projecting outside it reads the nearest border pixel: clamp-to-edge), and returns
  /// true; sets it to 0 and returns false when p is not in front of the camera. Branch-free, so
  /// loops over it vectorise (with gathers).
  bool locate(float x, float y, float z, int& index) const {
    const float inv = -1.0f / z;
    const bool valid = z < 0.0f;
    // Clamped as floats, before the conversion (which is undefined out of int's range); a NaN
    // (z = 0) is replaced by 0 first.
    const float fx = valid ? x * inv * scale_x + centre_x : 0.0f;
    const float fy = valid ? centre_y - y * inv * scale_y : 0.0f;
    const int ix = static_cast<int>(std::min(std::max(fx, 0.0f), static_cast<float>(width - 1)));
    const int iy = static_cast<int>(std::min(std::max(fy, 0.0f), static_cast<float>(height - 1)));
    index = iy * width + ix;
    return valid;
  }
};

}  // namespace ao
