// SPDX-License-Identifier: Apache-2.0
#include "ao/methods/characteristic.h"

#include <array>
#include <string>

#include "ao/core/error.h"

namespace ao {

ImplicitCharacteristic implicit_characteristic(const ImplicitSurface& surface, const Camera& camera) {
  const auto n = surface.primitives.size();
  if (n == 0 || n > static_cast<std::size_t>(ImplicitCharacteristic::kMaxPrimitives))
    throw InputError("implicit surface: " + std::to_string(n) + " primitives, the characteristic function takes 1 to " +
                     std::to_string(ImplicitCharacteristic::kMaxPrimitives));
  // The camera transform is rigid, so signed distances (f of a half-space, of a sphere exterior)
  // keep their values: f_camera(world_to_camera(p)) = f_world(p).
  ImplicitCharacteristic ch;
  for (const ImplicitSurfacePrimitive& q : surface.primitives) {
    if (q.kind == ImplicitSurfacePrimitive::Kind::HalfSpace)
      ch.add(ImplicitPrimitive::half_space(camera.world_to_camera_vector(q.normal), camera.world_to_camera_point(q.point)));
    else
      ch.add(ImplicitPrimitive::sphere_exterior(camera.world_to_camera_point(q.point), q.radius));
  }
  return ch;
}

HeightFieldCharacteristic height_field_characteristic(const HeightFieldSurface& surface, const Camera& camera) {
  if (!surface.map || surface.map->empty()) throw InputError("height field: the displacement map is empty");
  if (!(surface.period > 0.0f) || !std::isfinite(surface.period) || !std::isfinite(surface.amplitude))
    throw InputError("height field: period must be a finite number > 0 and amplitude finite");
  const Frame& f = surface.frame;
  constexpr float kTolerance = 1e-4f;  // float rounding of unit vectors built by hand
  for (Vec3 a : {f.t, f.b, f.n})
    if (std::abs(dot(a, a) - 1.0f) > kTolerance) throw InputError("height field: the frame's axes must be unit vectors");
  if (std::abs(dot(f.t, f.b)) > kTolerance || std::abs(dot(f.t, f.n)) > kTolerance || std::abs(dot(f.b, f.n)) > kTolerance)
    throw InputError("height field: the frame's axes must be orthogonal");
  // Rigid transform: the local coordinates (u, v, w) of a point are the same in both spaces.
  HeightFieldCharacteristic ch;
  ch.origin = camera.world_to_camera_point(surface.origin);
  ch.frame = {camera.world_to_camera_vector(f.t), camera.world_to_camera_vector(f.b), camera.world_to_camera_vector(f.n)};
  ch.map = surface.map->view();
  ch.period = surface.period;
  ch.amplitude = surface.amplitude;
  return ch;
}

namespace {
constexpr std::array<std::string_view, 4> kCharacteristicNames{"depth", "implicit", "height-field", "depth*height-field"};
}  // namespace

std::span<const std::string_view> characteristic_names() { return kCharacteristicNames; }
std::string_view to_string(CharacteristicKind kind) { return kCharacteristicNames[static_cast<std::size_t>(kind)]; }

}  // namespace ao
