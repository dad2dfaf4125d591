// SPDX-License-Identifier: Apache-2.0
// GBuffer: what every screen-space method reads. One entry per pixel, all in camera space
// (right-handed, looking down -z; see camera.h). Linear depth and coverage are not stored: they
// follow from the position and the object id (GBuffer::depth, GBuffer::covered), so rendering a
// G-buffer writes fewer bytes a pixel; kernels that gather depths build a contiguous plane with
// depth_plane() (simd/depth_plane.h).
#pragma once

#include <bit>
#include <cstdint>
#include <limits>

#include "ao/core/camera.h"
#include "ao/core/image.h"
#include "ao/core/math.h"

namespace ao {

/// Which normal a G-buffer's `normal` holds, and so which hemisphere every method integrates over.
enum class SurfaceNormal {
  Shading,    ///< Interpolated vertex normals: the smooth surface the mesh approximates (default).
  Geometric,  ///< The visible triangle's own normal: the integral of the faceted geometry as it is.
};

struct GBuffer {
  Camera camera;              ///< Intrinsics (fov, size) and, when known, the world placement.
  Image<Vec3> position;       ///< Camera-space position of the visible surface, z < 0; (0,0,0) where not covered.
  Image<Vec3> normal;         ///< Unit camera-space normal facing the camera (the shading normal unless rendered with SurfaceNormal::Geometric); (0,0,0) where not covered.
  Image<Vec3> albedo;         ///< Diffuse albedo in [0,1] per channel, linear; 0 where not covered. Empty when rendered without it (GBufferOptions::albedo).
  /// 1 + index of the object in its scene (Scene::objects(): the mesh, or a glTF instance of it)
  /// where a surface is visible; 0 where not covered (the background): this is the coverage
  /// (covered()).
  Image<std::uint32_t> object_id;
  Image<Vec2> uv;                  ///< First UV set of the visible surface; (0,0) where not covered or the mesh has none. Empty when rendered without it (GBufferOptions::uv).
  /// Optional direct-light pass: the radiance Ld the visible surface reflects of direct lights
  /// (sun, point lights; not the ambient light), per channel, in units of the ambient radiance La
  /// (Ld = 1: as bright as the sky), >= 0; 0 where not covered. Empty (the default) = no such
  /// pass. Read by ambient transfer's radiance mode (transfer.h) and by shading.
  Image<Vec3> direct;
  /// Optional: index of the visible triangle within mesh object_id - 1 (0 where not covered).
  /// Together with object_id it names the triangle, which lets ray-traced passes start their rays
  /// off it robustly (reference/ray_offset.h). Filled by render_gbuffer; empty when unknown (a
  /// G-buffer read from a file without a `primid` channel, or built by hand).
  Image<std::uint32_t> primitive_id;
  /// Optional second depth layer (a deep G-buffer, Mara et al. 2016; render_second_layer fills it):
  /// per pixel the signed linear depth of the nearest surface at least `second_separation` behind
  /// the visible one along the pixel's ray. > 0: a back face (the outward normal points along the
  /// ray: a closed mesh's by its signed volume, an open one's by open_mesh_facings, whatever the
  /// file's winding), where the solid entered at the visible surface ends; < 0: a front face (its depth
  /// negated): the visible surface was thinner than the separation and another solid begins there;
  /// +infinity: nothing behind (or not covered). Where the ray leaves a closed solid seen from
  /// outside (solid_exit_sides: a closed mesh, of either orientation, not around the eye) the depth
  /// is positive with the lowest bit of its float set (second_layer_back_face, a change of at
  /// most one unit in the last place), and every other positive depth has it clear: the ray entered that
  /// solid at the visible surface or within the separation behind it. Behind the wall of a room
  /// around the eye, kSecondLayerSolidOnward (no ray is traced). Empty (the default) = one layer.
  Image<float> second_depth;
  float second_separation = 0;  ///< The minimum separation second_depth was rendered with, world units.

  GBuffer() = default;
  explicit GBuffer(const Camera& cam)
      : camera(cam),
        position(cam.width, cam.height),
        normal(cam.width, cam.height),
        albedo(cam.width, cam.height),
        object_id(cam.width, cam.height, 0u),
        uv(cam.width, cam.height) {}

  int width() const { return camera.width; }
  int height() const { return camera.height; }
  /// True where a surface is visible (object_id != 0).
  bool covered(int x, int y) const { return object_id(x, y) != 0; }
  /// The same for pixel index i = y * width + x.
  bool covered(std::size_t i) const { return object_id[i] != 0; }
  /// Linear depth -position.z (> 0) where covered; +infinity where not.
  float depth(int x, int y) const { return covered(x, y) ? -position(x, y).z : kInfinity; }
  /// The same for pixel index i = y * width + x.
  float depth(std::size_t i) const { return covered(i) ? -position[i].z : kInfinity; }
};

/// GBuffer::second_depth's value for a back face at depth `t` > 0: the float's lowest bit set
/// where the ray leaves a closed solid seen from outside (`exits`), clear elsewhere.
inline float second_layer_back_face(float t, bool exits) {
  const std::uint32_t bits = std::bit_cast<std::uint32_t>(t);
  return std::bit_cast<float>(exits ? bits | 1u : bits & ~1u);
}
/// GBuffer::second_depth's value behind the wall of a room around the eye (a closed mesh the eye is
/// inside, whose solid is everything outside it): a back face at the largest finite depth, not an
/// exit, so the solid entered at the wall runs on without end.
inline const float kSecondLayerSolidOnward = second_layer_back_face(std::numeric_limits<float>::max(), false);
/// Whether a second-layer value (GBuffer::second_depth) is where the ray leaves a closed solid.
inline bool second_layer_exit(float s2) { return s2 > 0.0f && s2 < kInfinity && (std::bit_cast<std::uint32_t>(s2) & 1u) != 0; }

/// What a G-buffer renderer puts in the G-buffer (render_gbuffer: gbuffer/render_gbuffer.h;
/// GpuGBuffer::rasterize: gpu/gbuffer.h).
struct GBufferOptions {
  /// Which normal `normal` holds (and so which hemisphere every method integrates over). Default:
  /// shading, the smooth surface scanned and modelled meshes stand for (docs/methods/raytraced.md).
  SurfaceNormal normal = SurfaceNormal::Shading;
  /// Fill `albedo`. False leaves it empty, for passes that never read it (the ray-traced
  /// references take albedos from the scene): 12 bytes a pixel less to write. Default true.
  bool albedo = true;
  /// Fill `uv`. False leaves it empty: only sampling a baked map at the pixels reads it (`ao
  /// render --ao-map`). Default true.
  bool uv = true;
};

/// 1 where covered, 0 elsewhere: the mask the metrics (eval/metrics.h) take.
Image<std::uint8_t> coverage_mask(const GBuffer& g);

}  // namespace ao
