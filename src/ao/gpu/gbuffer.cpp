// SPDX-License-Identifier: Apache-2.0
// GpuScene and GpuGBuffer (gbuffer.h): scene upload, G-buffer upload and rasterization
// (shaders/gbuffer.vert, .geom, .frag; shaders/gbuffer_depth.comp), read-back.
#include "ao/gpu/gbuffer.h"

#include <algorithm>
#include <cmath>

#include "ao/core/error.h"
#include "ao/gpu/gl_internal.h"
#include "ao/gpu/resources_internal.h"

namespace ao {

namespace gpu_detail {

void GBufferTextures::bind() const {
  const Texture* units[] = {&depth, &position, &normal, &albedo, &object, &direct};
  for (GLuint u = 0; u < 6; ++u) {
    context->gl.ActiveTexture(GL_TEXTURE0 + u);
    context->gl.BindTexture(GL_TEXTURE_2D, units[u]->id());
  }
  context->gl.ActiveTexture(GL_TEXTURE0);
}

namespace {

// Mesh data for the vertex stage: positions, normals and (when the mesh has them) UVs, one
// attribute buffer each, and the indices.
Buffer array_buffer(Context& c, GLenum target, std::size_t bytes, const void* data) {
  GLuint id = 0;
  c.gl.GenBuffers(1, &id);
  Buffer b(c, id);
  c.gl.BindBuffer(target, id);
  c.gl.BufferData(target, static_cast<GLsizeiptr>(bytes), data, GL_STATIC_DRAW);
  return b;
}

void set_vec3(Context& c, Program& p, const char* name, Vec3 v) { c.gl.Uniform3f(c.uniform(p, name), v.x, v.y, v.z); }

}  // namespace

}  // namespace gpu_detail

using namespace gpu_detail;

GpuScene GpuScene::upload(GpuDevice& device, const Scene& scene) {
  Context& c = Access::context(device);
  c.make_current();
  auto b = std::make_shared<SceneBuffers>();
  b->context = Access::shared_context(device);
  b->scene = &scene;
  b->objects = scene.objects();
  for (const Mesh& m : scene.meshes) {
    // The vertex stage reads a normal (and, when there are any, a UV) per vertex: a scene that has
    // not passed validate_and_prepare may lack them, and an attribute read past its buffer is
    // undefined on a GPU.
    if (m.normals.size() != m.positions.size() || (!m.uvs.empty() && m.uvs.size() != m.positions.size()))
      throw InputError(scene.name + ": mesh '" + m.name + "' has no normal (or UV) for every vertex: the scene must pass validate_and_prepare");
    SceneBuffers::MeshBuffers mb;
    GLuint vao = 0;
    c.gl.GenVertexArrays(1, &vao);
    mb.vao = VertexArray(c, vao);
    c.gl.BindVertexArray(vao);
    mb.positions = array_buffer(c, GL_ARRAY_BUFFER, m.positions.size() * sizeof(Vec3), m.positions.data());
    c.gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vec3), nullptr);
    c.gl.EnableVertexAttribArray(0);
    mb.normals = array_buffer(c, GL_ARRAY_BUFFER, m.normals.size() * sizeof(Vec3), m.normals.data());
    c.gl.VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(Vec3), nullptr);
    c.gl.EnableVertexAttribArray(1);
    mb.has_uv = !m.uvs.empty();
    if (mb.has_uv) {
      mb.uvs = array_buffer(c, GL_ARRAY_BUFFER, m.uvs.size() * sizeof(Vec2), m.uvs.data());
      c.gl.VertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, sizeof(Vec2), nullptr);
      c.gl.EnableVertexAttribArray(2);
    } else {
      c.gl.DisableVertexAttribArray(2);  // the constant attribute below: UV (0, 0), as render_gbuffer
    }
    mb.indices = array_buffer(c, GL_ELEMENT_ARRAY_BUFFER, m.indices.size() * sizeof(std::uint32_t), m.indices.data());
    mb.index_count = static_cast<GLsizei>(m.indices.size());
    c.gl.BindVertexArray(0);
    b->meshes.push_back(std::move(mb));
  }
  c.check("uploading the scene's meshes");
  return GpuScene(std::move(b));
}

const Scene& GpuScene::scene() const { return *buffers_->scene; }

GpuGBuffer GpuGBuffer::upload(GpuDevice& device, const GBuffer& g) {
  Context& c = Access::context(device);
  c.make_current();
  const int w = g.width(), h = g.height();
  const auto fits = [&](const auto& img) { return img.width() == w && img.height() == h; };
  if (w < 1 || h < 1 || !fits(g.position) || !fits(g.normal) || !fits(g.object_id))
    throw InputError("--device gpu: the G-buffer to upload is empty, or its position, normal or object id differ from its camera's size");
  check_image_size(c, w, h);
  Program& p = c.program({"gbuffer_depth.comp"});
  std::vector<PassQuery> passes;
  c.begin_pass(passes, "upload");  // the copies and the depth pass
  auto t = std::make_shared<GBufferTextures>();
  t->context = Access::shared_context(device);
  t->camera = g.camera;
  t->position = make_texture(c, w, h, GL_RGBA32F);
  t->normal = make_texture(c, w, h, GL_RGBA32F);
  t->object = make_texture(c, w, h, GL_R32UI);
  t->depth = make_texture(c, w, h, GL_R32F);
  // Vec3 pixels go in as RGB into RGBA textures (alpha 1): no repacking on the CPU.
  gpu_detail::upload(c, t->position, GL_RGB, GL_FLOAT, g.position.data());
  gpu_detail::upload(c, t->normal, GL_RGB, GL_FLOAT, g.normal.data());
  gpu_detail::upload(c, t->object, GL_RED_INTEGER, GL_UNSIGNED_INT, g.object_id.data());
  if (!g.albedo.empty() && fits(g.albedo)) {
    t->albedo = make_texture(c, w, h, GL_RGBA32F);
    gpu_detail::upload(c, t->albedo, GL_RGB, GL_FLOAT, g.albedo.data());
    t->has_albedo = true;
  }
  if (!g.uv.empty() && fits(g.uv)) {
    t->uv = make_texture(c, w, h, GL_RG32F);
    gpu_detail::upload(c, t->uv, GL_RG, GL_FLOAT, g.uv.data());
    t->has_uv = true;
  }
  if (!g.primitive_id.empty() && fits(g.primitive_id)) {
    t->primitive = make_texture(c, w, h, GL_R32UI);
    gpu_detail::upload(c, t->primitive, GL_RED_INTEGER, GL_UNSIGNED_INT, g.primitive_id.data());
    t->has_primitive = true;
  }
  if (!g.direct.empty() && fits(g.direct)) {
    t->direct = make_texture(c, w, h, GL_RGBA32F);
    gpu_detail::upload(c, t->direct, GL_RGB, GL_FLOAT, g.direct.data());
  }
  c.gl.UseProgram(p.id);
  c.gl.Uniform2i(c.uniform(p, "u_size"), w, h);
  t->bind();
  bind_image(c, 0, t->depth, GL_WRITE_ONLY);
  dispatch_2d(c, w, h);
  c.end_pass(passes);
  c.check("deriving the uploaded G-buffer's depth");
  t->passes = c.resolve(passes);
  return GpuGBuffer(std::move(t));
}

namespace {

// The G-buffer's seven render targets and a depth buffer on one framebuffer, cleared to the
// background: P, N, albedo, ids, UV 0 and depth +infinity (docs/gbuffer.md); the depth test set
// for a buffer that holds near / depth (greater is nearer).
Framebuffer gbuffer_framebuffer(Context& c, const GBufferTextures& t, const Texture& z_buffer) {
  GLuint fbo_id = 0;
  c.gl.GenFramebuffers(1, &fbo_id);
  Framebuffer fbo(c, fbo_id);
  c.gl.BindFramebuffer(GL_FRAMEBUFFER, fbo_id);
  const Texture* targets[] = {&t.position, &t.normal, &t.albedo, &t.object, &t.primitive, &t.uv, &t.depth};
  GLenum draw[7];
  for (GLuint k = 0; k < 7; ++k) {
    c.gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + k, GL_TEXTURE_2D, targets[k]->id(), 0);
    draw[k] = GL_COLOR_ATTACHMENT0 + k;
  }
  c.gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, z_buffer.id(), 0);
  c.gl.DrawBuffers(7, draw);
  if (c.gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw SystemError("--device gpu: the G-buffer's render targets are not supported by " + c.renderer);
  return fbo;
}

void clear_to_background(Context& c) {
  const float zero[4] = {0, 0, 0, 0}, infinite[4] = {kInfinity, 0, 0, 0};
  const GLuint zero_u[4] = {0, 0, 0, 0};
  for (GLint k : {0, 1, 2, 5}) c.gl.ClearBufferfv(GL_COLOR, k, zero);
  for (GLint k : {3, 4}) c.gl.ClearBufferuiv(GL_COLOR, k, zero_u);
  c.gl.ClearBufferfv(GL_COLOR, 6, infinite);
  const float far_depth[1] = {0.0f};  // the depth buffer holds near / depth: 0 is infinitely far
  c.gl.ClearBufferfv(GL_DEPTH, 0, far_depth);
  c.gl.Enable(GL_DEPTH_TEST);
  c.gl.DepthFunc(GL_GREATER);
  c.gl.DepthMask(GL_TRUE);
}

// The camera's uniforms. The near plane: 1e-6 of the farthest depth of the scene's box (clip
// space needs one; the depth buffer holds near / depth in float, whose relative precision does not
// depend on it).
void set_camera(Context& c, Program& p, const Camera& camera, const Bounds3& bounds, const GBufferOptions& options) {
  const Frame basis = camera.basis();
  float farthest = 0;
  for (int k = 0; k < 8; ++k) {
    const Vec3 corner{k & 1 ? bounds.hi.x : bounds.lo.x, k & 2 ? bounds.hi.y : bounds.lo.y, k & 4 ? bounds.hi.z : bounds.lo.z};
    farthest = std::max(farthest, -basis.to_local(corner - camera.eye).z);
  }
  const float near = std::max(1e-6f * farthest, 1e-30f);
  const float tan_half = camera.tan_half_fov();
  set_vec3(c, p, "u_eye", camera.eye);
  set_vec3(c, p, "u_basis_x", basis.t);
  set_vec3(c, p, "u_basis_y", basis.b);
  set_vec3(c, p, "u_basis_z", basis.n);
  c.gl.Uniform3f(c.uniform(p, "u_clip"), 1.0f / (tan_half * camera.aspect()), 1.0f / tan_half, near);
  c.gl.Uniform2i(c.uniform(p, "u_size"), camera.width, camera.height);
  c.gl.Uniform2f(c.uniform(p, "u_tan_half"), tan_half, camera.aspect());
  c.gl.Uniform1i(c.uniform(p, "u_geometric"), options.normal == SurfaceNormal::Geometric ? 1 : 0);
}

// One draw per object, id o + 1; an instance's transform and its normals' (the cofactor matrix).
void draw_objects(Context& c, Program& p, const SceneBuffers& sb, const Scene& s) {
  for (std::size_t o = 0; o < sb.objects.size(); ++o) {
    const SceneObject& ob = sb.objects[o];
    const SceneBuffers::MeshBuffers& mb = sb.meshes[ob.mesh];
    const bool instance = ob.instance != SceneObject::kNoInstance;
    c.gl.Uniform1i(c.uniform(p, "u_instance"), instance ? 1 : 0);
    if (instance) {
      const Affine3& a = s.instances[ob.instance].object_to_world;
      const Affine3 n = cofactor(a);
      const float to_world[12] = {a.c0.x, a.c0.y, a.c0.z, a.c1.x, a.c1.y, a.c1.z, a.c2.x, a.c2.y, a.c2.z, a.c3.x, a.c3.y, a.c3.z};
      const float normal_to_world[9] = {n.c0.x, n.c0.y, n.c0.z, n.c1.x, n.c1.y, n.c1.z, n.c2.x, n.c2.y, n.c2.z};
      c.gl.Uniform3fv(c.uniform(p, "u_to_world"), 4, to_world);
      c.gl.Uniform3fv(c.uniform(p, "u_normal_to_world"), 3, normal_to_world);
    }
    c.gl.Uniform1ui(c.uniform(p, "u_object"), static_cast<GLuint>(o + 1));
    const Vec3 albedo = s.meshes[ob.mesh].albedo;
    set_vec3(c, p, "u_albedo", albedo);
    c.gl.BindVertexArray(mb.vao.id());
    if (!mb.has_uv) c.gl.VertexAttrib2f(2, 0.0f, 0.0f);
    c.gl.DrawElements(GL_TRIANGLES, mb.index_count, GL_UNSIGNED_INT, nullptr);
  }
  c.gl.BindVertexArray(0);
}

}  // namespace

GpuGBuffer GpuGBuffer::rasterize(GpuDevice& device, const GpuScene& scene, const Camera& camera, const GBufferOptions& options) {
  camera.validate();
  Context& c = Access::context(device);
  c.make_current();
  const SceneBuffers& sb = Access::buffers(scene);
  if (sb.context.get() != &c) throw InputError("--device gpu: the scene was uploaded to another device");
  const int w = camera.width, h = camera.height;
  check_image_size(c, w, h);
  auto t = std::make_shared<GBufferTextures>();
  t->context = sb.context;
  t->camera = camera;
  t->position = make_texture(c, w, h, GL_RGBA32F);
  t->normal = make_texture(c, w, h, GL_RGBA32F);
  t->albedo = make_texture(c, w, h, GL_RGBA32F);
  t->object = make_texture(c, w, h, GL_R32UI);
  t->primitive = make_texture(c, w, h, GL_R32UI);
  t->uv = make_texture(c, w, h, GL_RG32F);
  t->depth = make_texture(c, w, h, GL_R32F);
  t->has_albedo = options.albedo;
  t->has_uv = options.uv;
  t->has_primitive = true;
  Texture z_buffer = make_texture(c, w, h, GL_DEPTH_COMPONENT32F);
  Framebuffer fbo = gbuffer_framebuffer(c, *t, z_buffer);

  Program& p = c.program({"gbuffer.vert", "gbuffer.geom", "gbuffer.frag"});
  std::vector<PassQuery> passes;
  c.begin_pass(passes, "gbuffer");
  c.gl.Viewport(0, 0, w, h);
  clear_to_background(c);
  c.gl.UseProgram(p.id);
  set_camera(c, p, camera, scene.scene().bounds(), options);
  draw_objects(c, p, sb, scene.scene());
  c.end_pass(passes);
  c.gl.Disable(GL_DEPTH_TEST);
  c.gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  c.gl.MemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  c.check("rasterizing the G-buffer");
  t->passes = c.resolve(passes);
  return GpuGBuffer(std::move(t));
}

GBuffer GpuGBuffer::download() const {
  GBufferTextures& t = *textures_;
  Context& c = *t.context;
  c.make_current();
  const int w = t.camera.width, h = t.camera.height;
  GBuffer g;
  g.camera = t.camera;
  g.position = Image<Vec3>(w, h);
  g.normal = Image<Vec3>(w, h);
  g.object_id = Image<std::uint32_t>(w, h);
  gpu_detail::download(c, t.position, GL_RGB, GL_FLOAT, g.position.data(), g.position.size() * sizeof(Vec3));
  gpu_detail::download(c, t.normal, GL_RGB, GL_FLOAT, g.normal.data(), g.normal.size() * sizeof(Vec3));
  gpu_detail::download(c, t.object, GL_RED_INTEGER, GL_UNSIGNED_INT, g.object_id.data(), g.object_id.size() * sizeof(std::uint32_t));
  if (t.has_albedo) {
    g.albedo = Image<Vec3>(w, h);
    gpu_detail::download(c, t.albedo, GL_RGB, GL_FLOAT, g.albedo.data(), g.albedo.size() * sizeof(Vec3));
  } else {
    g.albedo = Image<Vec3>();
  }
  if (t.has_uv) {
    g.uv = Image<Vec2>(w, h);
    gpu_detail::download(c, t.uv, GL_RG, GL_FLOAT, g.uv.data(), g.uv.size() * sizeof(Vec2));
  } else {
    g.uv = Image<Vec2>();
  }
  if (t.has_primitive) {
    g.primitive_id = Image<std::uint32_t>(w, h);
    gpu_detail::download(c, t.primitive, GL_RED_INTEGER, GL_UNSIGNED_INT, g.primitive_id.data(), g.primitive_id.size() * sizeof(std::uint32_t));
  }
  if (t.direct) {
    g.direct = Image<Vec3>(w, h);
    gpu_detail::download(c, t.direct, GL_RGB, GL_FLOAT, g.direct.data(), g.direct.size() * sizeof(Vec3));
  }
  return g;
}

const Camera& GpuGBuffer::camera() const { return textures_->camera; }
int GpuGBuffer::width() const { return textures_->camera.width; }
int GpuGBuffer::height() const { return textures_->camera.height; }
const std::vector<GpuPassTime>& GpuGBuffer::passes() const { return textures_->passes; }

}  // namespace ao
