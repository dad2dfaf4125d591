// SPDX-License-Identifier: Apache-2.0
// Scenes and G-buffers in a GpuDevice's memory: what the GPU methods read (docs/gpu.md).
//
// A GpuGBuffer is made either by uploading a CPU G-buffer (render_gbuffer, a G-buffer file, your
// own depth and normal passes), so that both backends run on exactly the same input, or by
// rasterizing a GpuScene with the same camera and channel conventions as the CPU's ray-traced
// G-buffer (core/gbuffer.h, docs/gbuffer.md).
#pragma once

#include <memory>
#include <vector>

#include "ao/core/gbuffer.h"
#include "ao/gpu/device.h"
#include "ao/scene/mesh.h"

namespace ao {

namespace gpu_detail {
struct SceneBuffers;
struct GBufferTextures;
struct Access;
}  // namespace gpu_detail

/// A scene's meshes in a device's memory (vertex and index buffers, one draw per object of
/// Scene::objects(), instances through their transforms), for rasterizing G-buffers frame after
/// frame and voxelizing it for the cone method. The Scene is held by reference: it must outlive
/// this and not change (upload another for another scene). Copies share the buffers.
class GpuScene {
 public:
  /// Uploads every mesh of `scene` (which must have passed validate_and_prepare, as every loaded or
  /// built-in scene has). SystemError when the device runs out of memory.
  static GpuScene upload(GpuDevice& device, const Scene& scene);
  const Scene& scene() const;

 private:
  friend struct gpu_detail::Access;
  explicit GpuScene(std::shared_ptr<gpu_detail::SceneBuffers> b) : buffers_(std::move(b)) {}
  std::shared_ptr<gpu_detail::SceneBuffers> buffers_;
};

/// A G-buffer in a device's memory. Copies share the textures.
class GpuGBuffer {
 public:
  /// Uploads `g` (position, normal, object id, and albedo, UVs, triangle ids and the direct-light
  /// pass where `g` has them; the linear depth is derived on the GPU, as GBuffer::depth does).
  /// InputError when the image exceeds the device's largest texture.
  static GpuGBuffer upload(GpuDevice& device, const GBuffer& g);
  /// Rasterizes `scene` through `camera` (which must validate): per pixel centre the nearest
  /// surface's camera-space position (the pixel's ray met with the triangle's plane, as the ray
  /// tracer interpolates its hit), the normal `options` asks for turned to face the camera
  /// (the shading normal onto the geometric one's side), object id, triangle index, the mesh's
  /// albedo and the UVs, by the conventions of render_gbuffer (gbuffer/render_gbuffer.h). Triangles
  /// nearer the eye than 1e-6 of the scene's farthest depth are clipped (the ray tracer has no
  /// near plane). It agrees with render_gbuffer except on silhouette pixels (tests/gpu).
  static GpuGBuffer rasterize(GpuDevice& device, const GpuScene& scene, const Camera& camera, const GBufferOptions& options = {});

  /// Reads it back into a CPU G-buffer (albedo and UVs as `rasterize`'s options or the uploaded
  /// G-buffer had them; the direct-light pass when uploaded with one).
  GBuffer download() const;
  const Camera& camera() const;
  int width() const;
  int height() const;
  /// The GPU time of making it: "upload" (the depth pass after the copy) or "gbuffer" (rasterization).
  const std::vector<GpuPassTime>& passes() const;

 private:
  friend struct gpu_detail::Access;
  explicit GpuGBuffer(std::shared_ptr<gpu_detail::GBufferTextures> t) : textures_(std::move(t)) {}
  std::shared_ptr<gpu_detail::GBufferTextures> textures_;
};

}  // namespace ao
