// SPDX-License-Identifier: Apache-2.0
// Internals of the GPU backend, not installed: what GpuScene and GpuGBuffer hold (gbuffer.h).
#pragma once

#include <memory>
#include <vector>

#include "ao/core/camera.h"
#include "ao/gpu/gbuffer.h"
#include "ao/gpu/gl_internal.h"
#include "ao/core/typed_slots.h"

namespace ao::gpu_detail {

struct SceneBuffers {
  std::shared_ptr<Context> context;
  const Scene* scene = nullptr;
  struct MeshBuffers {
    VertexArray vao;
    Buffer positions, normals, uvs, indices;
    GLsizei index_count = 0;
    bool has_uv = false;
  };
  std::vector<MeshBuffers> meshes;
  std::vector<SceneObject> objects;
  /// What methods keep with the scene on the device (cone: its mesh closure and world voxel grid).
  TypedSlots state;
};

struct GBufferTextures {
  std::shared_ptr<Context> context;
  Camera camera;
  Texture depth, position, normal, albedo, object, primitive, uv, direct;
  bool has_albedo = false, has_uv = false, has_primitive = false;
  std::vector<GpuPassTime> passes;
  /// Binds the textures to the units of shaders/common.glsl (0 depth .. 5 direct); units of
  /// channels it lacks get no texture (texelFetch then reads 0).
  void bind() const;
};

/// What the backend's files reach inside the public classes.
struct Access {
  static Context& context(const GpuDevice& d) { return *d.context_; }
  static const std::shared_ptr<Context>& shared_context(const GpuDevice& d) { return d.context_; }
  static SceneBuffers& buffers(const GpuScene& s) { return *s.buffers_; }
  static GBufferTextures& textures(const GpuGBuffer& g) { return *g.textures_; }
};

}  // namespace ao::gpu_detail
