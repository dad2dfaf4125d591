// SPDX-License-Identifier: Apache-2.0
// Internal: where the ray-traced passes over a G-buffer (the ground truth, the sun) start their
// rays from a pixel: its world position, its normal, the geometric normal of the triangle it lies
// on, and the robust offset of ray_offset.h.
#pragma once

#include <algorithm>
#include <vector>

#include "ao/core/gbuffer.h"
#include "ao/reference/ray_offset.h"
#include "ao/scene/mesh.h"

namespace ao::detail {

struct PixelSurface {
  Vec3 position;  ///< World space, on the surface.
  Vec3 normal;    ///< Unit world-space normal of the G-buffer (shading or geometric, as rendered).
  Vec3 geometric; ///< Unit geometric normal of the triangle, on the side of `normal`; `normal` when the triangle is unknown.
  float offset;   ///< Distance to move the ray origin along `geometric` (ray_offset.h), or the user's fixed offset.
};

/// What pixel-to-world needs once per image.
struct PixelSurfaceContext {
  const GBuffer& g;
  const Scene& scene;
  std::vector<SceneObject> objects;  // scene.objects(): object id - 1 -> mesh and instance
  Frame basis;
  Vec3 eye;
  float eye_magnitude;    // largest coordinate of the eye
  float scene_magnitude;  // largest coordinate of the scene: the offset scale when the triangle is unknown
  float fixed_offset;     // > 0: use this instead of the scale-free offset
  bool has_triangles;     // the G-buffer names the triangle of each pixel (primitive_id)

  PixelSurfaceContext(const GBuffer& gb, const Scene& s, const Bounds3& bounds, float fixed)
      : g(gb),
        scene(s),
        objects(s.objects()),
        basis(gb.camera.basis()),
        eye(gb.camera.eye),
        eye_magnitude(max_abs_coordinate(gb.camera.eye)),
        scene_magnitude(std::max(max_abs_coordinate(bounds.lo), max_abs_coordinate(bounds.hi))),
        fixed_offset(fixed),
        has_triangles(gb.primitive_id.width() == gb.width() && gb.primitive_id.height() == gb.height()) {}

  /// Pixel (x, y), which must be covered.
  PixelSurface operator()(int x, int y) const {
    const Vec3 pc = g.position(x, y);
    PixelSurface s;
    s.position = basis.to_world(pc) + eye;
    s.normal = normalize(basis.to_world(g.normal(x, y)));
    s.geometric = s.normal;
    // The world position went through camera space: its rounding is of the size of the eye's and
    // the camera-space coordinates, on top of the triangle's own.
    float magnitude = eye_magnitude + max_abs_coordinate(pc);
    const std::uint32_t id = g.object_id(x, y);
    const std::size_t tri = has_triangles ? g.primitive_id(x, y) : 0;
    if (has_triangles && id >= 1 && id <= objects.size() && tri < scene.meshes[objects[id - 1].mesh].triangle_count()) {
      // The triangle in world space (an instance's moved vertex by vertex, as the G-buffer did).
      const SceneObject& o = objects[id - 1];
      const Mesh& m = scene.meshes[o.mesh];
      const std::uint32_t* i = &m.indices[3 * tri];
      Vec3 p[3] = {m.positions[i[0]], m.positions[i[1]], m.positions[i[2]]};
      if (o.instance != SceneObject::kNoInstance)
        for (Vec3& q : p) q = scene.instances[o.instance].object_to_world.point(q);
      const Vec3 ng = normalize(cross(p[1] - p[0], p[2] - p[0]));
      s.geometric = dot(ng, s.normal) < 0 ? -ng : ng;
      magnitude = std::max({magnitude, max_abs_coordinate(p[0]), max_abs_coordinate(p[1]), max_abs_coordinate(p[2])});
    } else {
      magnitude = std::max(magnitude, scene_magnitude);
    }
    s.offset = fixed_offset > 0 ? fixed_offset : ray_offset_distance(magnitude);
    return s;
  }
};

}  // namespace ao::detail
