// SPDX-License-Identifier: Apache-2.0
// Characteristic functions I(p) of volumetric-ambient-occlusion (VAO), fig. 2, and ambient
// transfer (AT) sec. 4: I(p) = 1 when camera-space point p is in the OUTER region (where the
// camera is) and 0 in the inner region. Every function here also gives the distance from p to
// the separating surface along the view axis, which volumetric AO needs (VAO, the paragraph after
// fig. 2) and silhouette-shadow elimination uses (AT sec. 4.3):
//
//   distance(p) = z* - depth(p),  depth(p) = -p.z (camera looks down -z)
//
// > 0 when p is in front of the surface (outer), < 0 behind it (inner), +infinity when no
// surface is crossed along the view axis. I(p) = [distance(p) >= -bias].
//
// Kinds (each a small, cheap-to-copy value type with an inline `distance`, so kernels templated
// on the type copy it into locals and inline it into their vectorised loops; no virtual calls):
//  - DepthBufferCharacteristic: the G-buffer's depth at p's projection (VAO fig. 2c). Points
//    projecting outside the image read the nearest border pixel (clamp-to-edge: the surfaces at
//    the frame's edge go on beyond it); points on background, or behind the camera, are free
//    (distance = +infinity).
//  - ImplicitCharacteristic: f(p) >= 0 for f = min of analytic primitives (planes, sphere
//    exteriors), with the Taylor distance z* - p_z ~ -f / (df/dz) (VAO, eq. after fig. 2).
//  - HeightFieldCharacteristic: a displacement map in a surface's tangent space, p_n >= h(p_t, p_b)
//    (VAO fig. 2b), distance by the same Taylor step.
//  - ProductCharacteristic: the product of two (VAO fig. 12: depth buffer x height field); the
//    nearer separating surface bounds the free part of a pipe, so distance = min.
//  - SilhouetteEliminated: AT sec. 4.3 applied to one factor of a product (the depth buffer's).
// The analytic kinds are made from a scene's world-space description (scene/analytic.h) by
// implicit_characteristic and height_field_characteristic.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "ao/core/camera.h"
#include "ao/core/gbuffer.h"
#include "ao/core/image.h"
#include "ao/core/math.h"
#include "ao/core/params.h"
#include "ao/scene/analytic.h"
#include "ao/simd/depth_plane.h"

namespace ao {

/// VAO fig. 2c: the z-buffer separates inner from outer. z* is the linear depth stored at p's pixel
/// (nearest pixel, clamped to the image); background pixels hold +infinity, so they are free.
struct DepthBufferCharacteristic {
  ScreenProjection projection;
  std::shared_ptr<const Image<float>> plane;  ///< The G-buffer's depth_plane(), built once and shared by copies.
  const float* depth = nullptr;               ///< The depth read, width * height values: plane's.

  /// The deep G-buffer's second layer (GBuffer::second_depth's signed encoding), or null: one
  /// layer. The SIMD kernels read it (depth_layers.h states the solid it describes); distance()
  /// below is the first layer's, which is all a product of characteristics takes.
  std::shared_ptr<const Image<float>> second_plane;
  const float* second = nullptr;
  float separation = 0;  ///< The second layer's minimum separation, world units.
  /// With the second layer: the G-buffer's normals (3 floats a pixel, facing the camera), which the
  /// kernels read behind a sheet. Not owned: the G-buffer must outlive this.
  const float* normals = nullptr;

  explicit DepthBufferCharacteristic(const GBuffer& g) : DepthBufferCharacteristic(g, std::make_shared<const Image<float>>(depth_plane(g))) {}
  /// On a depth plane built already (`built`: depth_plane(g)), e.g. one a caller keeps between frames.
  DepthBufferCharacteristic(const GBuffer& g, std::shared_ptr<const Image<float>> built)
      : projection(ScreenProjection::from_camera(g.camera)), plane(std::move(built)), depth(plane->data()) {}
  /// With a second layer (`layer`: the G-buffer's size, rendered at `separation`).
  DepthBufferCharacteristic(const GBuffer& g, std::shared_ptr<const Image<float>> layer, float layer_separation)
      : DepthBufferCharacteristic(g) {
    add_second_layer(g, std::move(layer), layer_separation);
  }
  /// Reads `layer` (the G-buffer's size, rendered at `layer_separation`) as the second layer too.
  void add_second_layer(const GBuffer& g, std::shared_ptr<const Image<float>> layer, float layer_separation) {
    second_plane = std::move(layer);
    second = second_plane->data();
    separation = layer_separation;
    static_assert(sizeof(Vec3) == 3 * sizeof(float), "the kernels gather a normal's components at 3 i + k");
    if (g.normal.size() != g.position.size()) throw InputError("the second depth layer reads the G-buffer's normals, and it has none");
    normals = reinterpret_cast<const float*>(g.normal.data());
  }

  float distance(float x, float y, float z) const {
    int i;
    const bool valid = projection.locate(x, y, z, i);
    const float zs = depth[i];  // index 0 behind the camera: always readable, so the gather is unconditional
    return valid ? zs + z : kInfinity;  // z* - depth(p) with depth(p) = -z
  }
};

/// One analytic primitive of an implicit surface, in camera space. f >= 0 outside.
struct ImplicitPrimitive {
  enum class Kind { HalfSpace, SphereExterior } kind = Kind::HalfSpace;
  Vec3 normal{0, 0, 1};  ///< HalfSpace: unit normal pointing into the outer region.
  float offset = 0;      ///< HalfSpace: f = dot(normal, p) - offset.
  Vec3 centre{};         ///< SphereExterior: f = |p - centre| - radius.
  float radius = 1;

  static ImplicitPrimitive half_space(Vec3 n, Vec3 point_on_plane) {
    const Vec3 u = normalize(n);
    return {Kind::HalfSpace, u, dot(u, point_on_plane), {}, 1};
  }
  static ImplicitPrimitive sphere_exterior(Vec3 c, float r) { return {Kind::SphereExterior, {}, 0, c, r}; }

  float value(Vec3 p) const { return kind == Kind::HalfSpace ? dot(normal, p) - offset : length(p - centre) - radius; }
  Vec3 gradient(Vec3 p) const { return kind == Kind::HalfSpace ? normal : normalize(p - centre); }
};

/// Taylor step of VAO (eq. after fig. 2) for one implicit function with value f and gradient g:
/// along the depth direction (0, 0, -1) the surface is at depth offset -f / (df/d depth) with
/// df/d depth = -g.z. Where the surface does not get nearer going deeper (df/d depth >= 0) the
/// line never enters the inner region ahead of p: +infinity from outside, -FLT_MAX from inside
/// (inner along the whole line, finite so that "d > -infinity" comparisons hold).
inline float taylor_depth_distance(float f, float gz) {
  constexpr float kFlat = 1e-6f;  // |df/d depth| below this: the line runs along the surface
  if (gz <= kFlat) return f >= 0.0f ? kInfinity : -std::numeric_limits<float>::max();
  return f / gz;
}

/// VAO fig. 2a: I(p) = [f(p) >= 0] with f = min over the primitives (the outer region is the
/// intersection of theirs: a floor and a wall make a wedge, a plane and a sphere exterior make a
/// sphere resting on a plane). The distance is the nearest surface crossing ahead, the minimum of
/// the primitives' Taylor distances.
struct ImplicitCharacteristic {
  static constexpr int kMaxPrimitives = 4;
  std::array<ImplicitPrimitive, kMaxPrimitives> primitives{};  ///< The first `count` are used.
  int count = 0;

  /// Adds a primitive; at most kMaxPrimitives (the type stays a cheap-to-copy value).
  ImplicitCharacteristic& add(const ImplicitPrimitive& q) {
    AO_ASSERT(count < kMaxPrimitives);
    primitives[static_cast<std::size_t>(count++)] = q;
    return *this;
  }
  float distance(float x, float y, float z) const {
    const Vec3 p{x, y, z};
    float d = kInfinity;
    for (int k = 0; k < count; ++k) {
      const ImplicitPrimitive& q = primitives[static_cast<std::size_t>(k)];
      d = std::min(d, taylor_depth_distance(q.value(p), q.gradient(p).z));
    }
    return d;
  }
};

/// VAO fig. 2b: a displacement map over a macrostructure plane, seen in the plane's tangent frame
/// (camera space). With local coordinates (u, v, w) = ((p - origin) . tangent, . bitangent, . normal),
/// I(p) = [w >= h(u, v)], h = amplitude * bilinear lookup of `map` tiled every `period` world units.
struct HeightFieldCharacteristic {
  Vec3 origin{};            ///< A point of the macrostructure plane, camera space.
  Frame frame{};            ///< Tangent, bitangent, normal (towards the outer side), camera space.
  ImageView<const float> map;  ///< Heights in [0, 1] (any values work), tiled; non-empty; must outlive this.
  float period = 1.0f;      ///< World units covered by the map along u and v, > 0.
  float amplitude = 0.1f;   ///< World units of height for map value 1.

  /// h(u, v), world units.
  float height(float u, float v) const {
    const float fx = u / period * static_cast<float>(map.width) - 0.5f;
    const float fy = v / period * static_cast<float>(map.height) - 0.5f;
    const float x0 = std::floor(fx), y0 = std::floor(fy);
    const float ax = fx - x0, ay = fy - y0;
    auto at = [&](float xi, float yi) {
      const int w = map.width, h = map.height;
      const int ix = ((static_cast<int>(xi) % w) + w) % w, iy = ((static_cast<int>(yi) % h) + h) % h;
      return map(ix, iy);
    };
    const float top = at(x0, y0) * (1 - ax) + at(x0 + 1, y0) * ax;
    const float bottom = at(x0, y0 + 1) * (1 - ax) + at(x0 + 1, y0 + 1) * ax;
    return amplitude * (top * (1 - ay) + bottom * ay);
  }
  /// f(p) = w - h(u, v) (>= 0 outside) and its camera-space gradient, by central differences of h
  /// over a tenth of a texel (the bilinear h is piecewise smooth).
  float value(Vec3 p, Vec3* gradient) const {
    const Vec3 l = frame.to_local(p - origin);
    const float f = l.z - height(l.x, l.y);
    if (gradient) {
      const float e = 0.1f * period / static_cast<float>(std::max(map.width, map.height));
      const float hu = (height(l.x + e, l.y) - height(l.x - e, l.y)) / (2 * e);
      const float hv = (height(l.x, l.y + e) - height(l.x, l.y - e)) / (2 * e);
      *gradient = frame.to_world({-hu, -hv, 1.0f});
    }
    return f;
  }
  float distance(float x, float y, float z) const {
    Vec3 g;
    const float f = value({x, y, z}, &g);
    return taylor_depth_distance(f, g.z);
  }
};

/// VAO fig. 12: I = I_a * I_b. A point is free when both say so; along a pipe the nearer of the
/// two separating surfaces ends the free part.
template <class A, class B>
struct ProductCharacteristic {
  A a;
  B b;
  float distance(float x, float y, float z) const { return std::min(a.distance(x, y, z), b.distance(x, y, z)); }
};

/// AT sec. 4.3 as a characteristic function: a surface more than `limit` in front of p (distance <
/// -limit) is taken for a distant foreground object with free space behind it, so p counts as outer
/// (distance +infinity). The kernels apply the same test to the whole characteristic
/// (`silhouette_elimination`); this wrapper applies it to one factor of a product, so that an
/// analytic factor, whose inner region really is solid, keeps its points inner however far in
/// front its surface is. limit = +infinity: no elimination.
template <class C>
struct SilhouetteEliminated {
  C inner;
  float limit = kInfinity;  ///< World units along the view axis, > 0.
  float distance(float x, float y, float z) const {
    const float d = inner.distance(x, y, z);
    return d < -limit ? kInfinity : d;
  }
};

using DepthTimesHeightField = ProductCharacteristic<DepthBufferCharacteristic, HeightFieldCharacteristic>;
/// VAO fig. 12 with the depth buffer's silhouette shadows eliminated and the height field's kept
/// (what `characteristic=depth*height-field` of the registry runs).
using EliminatedDepthTimesHeightField = ProductCharacteristic<SilhouetteEliminated<DepthBufferCharacteristic>, HeightFieldCharacteristic>;

/// The G-buffer depth plane a characteristic function carries (DepthBufferCharacteristic's), else
/// null: the filter after a pass reuses it instead of building another.
template <class C>
const Image<float>* carried_depth_plane(const C& ch) {
  if constexpr (std::is_same_v<C, DepthBufferCharacteristic>) return ch.plane.get();
  else return nullptr;
}

/// The scene's implicit surface (world space) as a characteristic function in the camera space of
/// `camera`. InputError when it has no primitive or more than ImplicitCharacteristic::kMaxPrimitives.
ImplicitCharacteristic implicit_characteristic(const ImplicitSurface& surface, const Camera& camera);

/// The scene's height field (world space) in the camera space of `camera`. The map is shared, not
/// copied: `surface.map` must outlive the result. InputError for an empty map, a non-positive or
/// non-finite period, or a frame that is not orthonormal.
HeightFieldCharacteristic height_field_characteristic(const HeightFieldSurface& surface, const Camera& camera);

/// Which characteristic function I(p) containment, volumetric and transfer read (their parameter
/// `characteristic`; VAO fig. 2 and 12). The method's run builds it in the G-buffer's camera space
/// (screen_space_method_internal.h).
enum class CharacteristicKind {
  Depth,                  ///< "depth": the G-buffer's depth buffer (fig. 2c), with AT 4.3's silhouette elimination as asked.
  Implicit,               ///< "implicit": the scene's half-spaces and sphere exteriors (fig. 2a); no silhouette elimination.
  HeightField,            ///< "height-field": the scene's displacement map over its macro plane (fig. 2b), alone.
  DepthTimesHeight,       ///< "depth*height-field": their product (fig. 12); elimination applies to the depth factor only.
};
/// The parameter of containment, volumetric and transfer that holds their CharacteristicKind.
inline constexpr const char* kCharacteristicParam = "characteristic";
/// The names of CharacteristicKind's values, in its order: "depth", "implicit", "height-field",
/// "depth*height-field".
std::span<const std::string_view> characteristic_names();
/// The name of `kind`.
std::string_view to_string(CharacteristicKind kind);

/// The `characteristic` row of a screen-space method's parameter table, for member `member`.
template <class P>
Param<P> characteristic_param(CharacteristicKind P::*member) {
  std::vector<std::pair<std::string, CharacteristicKind>> names;
  for (std::size_t k = 0; k < characteristic_names().size(); ++k)
    names.emplace_back(characteristic_names()[k], static_cast<CharacteristicKind>(k));
  return Param<P>::enumeration(kCharacteristicParam, member, std::move(names),
                               "the characteristic function I(p): depth buffer, the scene's implicit surface or height field, or depth x height field");
}

}  // namespace ao
