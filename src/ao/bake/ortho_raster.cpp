// SPDX-License-Identifier: Apache-2.0
// The flattened mesh and the orthographic views of the outside-in baker; the rasteriser itself
// (a half-space rasteriser for many small triangles) is simd::rasterize_front_faces.
#include "ao/bake/ortho_raster.h"

#include <cmath>

#include "ao/bake/texel_coverage.h"
#include "ao/bake/histogram_kernel_internal.h"

namespace ao {

RasterMesh make_raster_mesh(const Scene& scene, int map_width, int map_height) {
  require_no_instances(scene);
  RasterMesh r;
  Bounds3 bounds;
  for (std::size_t mi = 0; mi < scene.meshes.size(); ++mi) {
    const Mesh& m = scene.meshes[mi];
    const auto base = static_cast<std::uint32_t>(r.positions.size());
    r.first_vertex.push_back(base);
    const bool uv = !m.uvs.empty() && map_width > 0 && map_height > 0;
    for (std::size_t v = 0; v < m.positions.size(); ++v) {
      r.positions.push_back(m.positions[v]);
      r.normals.push_back(m.normals.empty() ? Vec3{0, 0, 1} : m.normals[v]);
      r.uvs.push_back(uv ? texel_uv(m, static_cast<std::uint32_t>(v), map_width, map_height) : Vec2{});
      bounds.extend(m.positions[v]);
    }
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      const std::uint32_t* i = &m.indices[3 * t];
      for (int k = 0; k < 3; ++k) r.indices.push_back(base + i[k]);
      const Vec3 a = m.positions[i[0]], b = m.positions[i[1]], c = m.positions[i[2]];
      const double world = 0.5 * length(cross(b - a, c - a));
      r.surface_area += world;
      float s = 0;
      if (uv) {
        const Vec2 ua = r.uvs[base + i[0]], ub = r.uvs[base + i[1]], uc = r.uvs[base + i[2]];
        const double area_uv = 0.5 * std::abs((static_cast<double>(ub.x) - ua.x) * (uc.y - ua.y) - (static_cast<double>(uc.x) - ua.x) * (ub.y - ua.y));
        s = area_uv > 0 ? static_cast<float>(world / area_uv) : 0.0f;
      }
      r.has_uv.push_back(uv && s > 0 ? 1 : 0);
      r.stretch.push_back(s);
      r.mesh_of.push_back(static_cast<std::uint32_t>(mi));
    }
  }
  r.center = bounds.center();
  for (const Vec3& p : r.positions) r.radius = std::max(r.radius, length(p - r.center));
  return r;
}

OrthoView make_ortho_view(const RasterMesh& mesh, Vec3 w, float pixel_size, Vec2 jitter) {
  OrthoView v;
  v.frame = Frame::from_normal(w);
  v.pixel_size = pixel_size;
  // One pixel of margin on each side plus the jitter, so the whole sphere is always inside.
  const int n = static_cast<int>(std::ceil(2.0f * mesh.radius / pixel_size)) + 3;
  v.width = v.height = n;
  v.origin = mesh.center - (v.frame.t + v.frame.b) * (mesh.radius + (1.0f + 0.0f) * pixel_size) - v.frame.t * (jitter.x * pixel_size) -
             v.frame.b * (jitter.y * pixel_size);
  return v;
}

void rasterize(const RasterMesh& mesh, const OrthoView& view, RasterTarget& target) {
  const std::size_t nv = mesh.positions.size();
  target.px.resize(nv);
  target.py.resize(nv);
  target.pz.resize(nv);
  const int w = view.width, h = view.height;
  if (target.depth.width() != w || target.depth.height() != h) {
    target.depth = Image<float>(w, h);
    target.id = Image<std::uint32_t>(w, h);
  }
  // The rasteriser itself runs in a SIMD kernel (histogram_kernel.cpp), compiled for every x86-64 target.
  const simd::RasterInput in{mesh.positions.data(), nv, mesh.indices.data(), mesh.triangle_count(), view.frame, view.origin, view.pixel_size, w, h};
  simd::rasterize_front_faces(in, target.px.data(), target.py.data(), target.pz.data(), target.depth.data(), target.id.data());
}

}  // namespace ao
