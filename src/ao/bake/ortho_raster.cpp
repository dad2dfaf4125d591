// A half-space rasteriser tuned for what baking feeds it: many small triangles (an 89k-triangle
// mesh at map resolution covers a few pixels each), one orthographic view per direction. Each
// triangle is set up once (bounding box, three edge functions, a depth plane), then its box is
// scanned with incremental edge functions. No tiles, no SIMD: the per-direction images are a few
// hundred thousand pixels, which fit in L2 with the projected vertices.
#include "ao/bake/ortho_raster.h"

#include <cmath>

#include "ao/bake/texel_coverage.h"

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
  const float inv = 1.0f / view.pixel_size;
  const Frame& f = view.frame;
  for (std::size_t i = 0; i < nv; ++i) {
    const Vec3 p = mesh.positions[i] - view.origin;
    target.px[i] = dot(p, f.t) * inv;
    target.py[i] = dot(p, f.b) * inv;
    target.pz[i] = dot(mesh.positions[i], f.n);
  }
  const int w = view.width, h = view.height;
  if (target.depth.width() != w || target.depth.height() != h) {
    target.depth = Image<float>(w, h);
    target.id = Image<std::uint32_t>(w, h);
  }
  std::fill(target.depth.pixels().begin(), target.depth.pixels().end(), -kInfinity);
  std::fill(target.id.pixels().begin(), target.id.pixels().end(), 0u);
  float* depth = target.depth.data();
  std::uint32_t* ids = target.id.data();
  const float* px = target.px.data();
  const float* py = target.py.data();
  const float* pz = target.pz.data();

  const std::size_t nt = mesh.triangle_count();
  for (std::size_t t = 0; t < nt; ++t) {
    const std::uint32_t i0 = mesh.indices[3 * t], i1 = mesh.indices[3 * t + 1], i2 = mesh.indices[3 * t + 2];
    const float ax = px[i0], ay = py[i0], bx = px[i1], by = py[i1], cx = px[i2], cy = py[i2];
    // Twice the signed image area; (t, b, w) is right-handed, so a counter-clockwise front face
    // seen from the light has area > 0. Back faces and edge-on faces are culled.
    const float area2 = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay);
    if (!(area2 > 0)) continue;
    // Pixel centres (i + 0.5) inside the bounding box.
    const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({ax, bx, cx}) - 0.5f)));
    const int x1 = std::min(w - 1, static_cast<int>(std::floor(std::max({ax, bx, cx}) - 0.5f)));
    const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({ay, by, cy}) - 0.5f)));
    const int y1 = std::min(h - 1, static_cast<int>(std::floor(std::max({ay, by, cy}) - 0.5f)));
    if (x0 > x1 || y0 > y1) continue;
    // Edge functions E(p) = (q1 - q0) x (p - q0), positive inside. Tie rule for centres exactly on
    // an edge: keep them for edges whose direction is "positive" (dy > 0, or dy = 0 and dx > 0).
    // The two triangles sharing an edge traverse it in opposite directions, so exactly one keeps them.
    struct Edge {
      float a, b, c;  // E = a x + b y + c
      bool keep_zero;
    };
    auto edge = [](float qx0, float qy0, float qx1, float qy1) {
      const float dx = qx1 - qx0, dy = qy1 - qy0;
      return Edge{-dy, dx, dy * qx0 - dx * qy0, dy > 0 || (dy == 0 && dx > 0)};
    };
    const Edge e0 = edge(bx, by, cx, cy);  // opposite a: barycentric of a
    const Edge e1 = edge(cx, cy, ax, ay);  // opposite b
    const Edge e2 = edge(ax, ay, bx, by);  // opposite c
    const float inv_area = 1.0f / area2;
    const float za = pz[i0], zb = pz[i1], zc = pz[i2];
    // Depth plane z = za + l1 (zb - za) + l2 (zc - za), with l1 = E1 / area2, l2 = E2 / area2.
    const float dz1 = (zb - za) * inv_area, dz2 = (zc - za) * inv_area;
    const float zx = e1.a * dz1 + e2.a * dz2, zy = e1.b * dz1 + e2.b * dz2, zc0 = za + e1.c * dz1 + e2.c * dz2;
    const auto tri_id = static_cast<std::uint32_t>(t + 1);
    for (int y = y0; y <= y1; ++y) {
      const float fy = static_cast<float>(y) + 0.5f;
      const float fx0 = static_cast<float>(x0) + 0.5f;
      float w0 = e0.a * fx0 + e0.b * fy + e0.c;
      float w1 = e1.a * fx0 + e1.b * fy + e1.c;
      float w2 = e2.a * fx0 + e2.b * fy + e2.c;
      float z = zx * fx0 + zy * fy + zc0;
      const std::size_t row = static_cast<std::size_t>(y) * w;
      for (int x = x0; x <= x1; ++x) {
        const bool inside = (w0 > 0 || (w0 == 0 && e0.keep_zero)) && (w1 > 0 || (w1 == 0 && e1.keep_zero)) && (w2 > 0 || (w2 == 0 && e2.keep_zero));
        if (inside && z > depth[row + x]) {
          depth[row + x] = z;
          ids[row + x] = tri_id;
        }
        w0 += e0.a;
        w1 += e1.a;
        w2 += e2.a;
        z += zx;
      }
    }
  }
}

}  // namespace ao
