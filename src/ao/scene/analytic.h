// SPDX-License-Identifier: Apache-2.0
// Analytic descriptions of a scene's surfaces in world space, for the characteristic functions of
// Szirmay-Kalos et al., "Volumetric Ambient Occlusion" (VAO), fig. 2: (a) an implicit surface made
// of half-spaces and sphere exteriors, (b) a height field over a macrostructure plane. Built-in
// scenes that are exactly such surfaces carry them (procedural.h); scenes read from files have
// none. methods/characteristic.h turns them into camera-space characteristic functions.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "ao/core/image.h"
#include "ao/core/math.h"

namespace ao {

/// One primitive of an implicit surface, world space, with f >= 0 on its outer side (the side the
/// scene is seen from).
struct ImplicitSurfacePrimitive {
  enum class Kind { HalfSpace, SphereExterior } kind = Kind::HalfSpace;
  Vec3 point{};          ///< HalfSpace: a point of the plane. SphereExterior: the centre.
  Vec3 normal{0, 1, 0};  ///< HalfSpace: unit normal pointing into the outer region.
  float radius = 1.0f;   ///< SphereExterior: radius, world units, > 0.

  static ImplicitSurfacePrimitive half_space(Vec3 point_on_plane, Vec3 outward_normal) {
    return {Kind::HalfSpace, point_on_plane, normalize(outward_normal), 1.0f};
  }
  static ImplicitSurfacePrimitive sphere_exterior(Vec3 centre, float radius) { return {Kind::SphereExterior, centre, {0, 1, 0}, radius}; }

  /// f(p): signed distance to the plane, or to the sphere; >= 0 outside.
  float value(Vec3 p) const { return kind == Kind::HalfSpace ? dot(normal, p - point) : length(p - point) - radius; }
};

/// VAO fig. 2a: the outer region is the intersection of the primitives' outer regions, f = min_k f_k
/// (a floor and a wall make a wedge; a floor and a sphere exterior, a sphere resting on it).
struct ImplicitSurface {
  std::vector<ImplicitSurfacePrimitive> primitives;

  /// min_k f_k(p), +infinity without primitives.
  float value(Vec3 p) const {
    float f = kInfinity;
    for (const ImplicitSurfacePrimitive& q : primitives) f = std::min(f, q.value(p));
    return f;
  }
};

/// VAO fig. 2b: a displacement map over a macrostructure plane. With (u, v, w) =
/// frame.to_local(p - origin), p is outer when w >= amplitude * map(u, v), the map read bilinearly
/// with texel centres at ((i + 1/2) period / width, (j + 1/2) period / height) and tiled every
/// `period` world units along u and v (HeightFieldCharacteristic::height is that lookup).
struct HeightFieldSurface {
  Vec3 origin{};                                  ///< A point of the macrostructure plane, world units.
  Frame frame{{1, 0, 0}, {0, 0, 1}, {0, 1, 0}};  ///< Orthonormal: u axis, v axis, normal (towards the outer side), world space.
  std::shared_ptr<const Image<float>> map;        ///< Heights (any finite values; [0, 1] in the built-ins), non-empty. Shared: copying a Scene stays cheap.
  float period = 1.0f;                            ///< World units covered by the map along u and v, > 0.
  float amplitude = 0.1f;                         ///< World units of height for map value 1.
};

/// Everything analytic a scene knows about its surfaces; each part is absent when the scene is not
/// exactly that surface.
struct AnalyticSurfaces {
  std::optional<ImplicitSurface> implicit;          ///< The whole scene as an implicit surface.
  std::optional<HeightFieldSurface> height_field;  ///< A displacement-mapped surface of the scene (others may stand on it).
};

/// A periodic displacement map: `bumps` x `bumps` smooth domes (cos^2 profile, height 1 at their
/// centres, 0 outside the cell's inscribed circle) on a size x size map. size >= bumps >= 1.
Image<float> make_bump_map(int size, int bumps);

}  // namespace ao
