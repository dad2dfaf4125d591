// SPDX-License-Identifier: Apache-2.0
#include "ao/eval/shading.h"

#include <algorithm>

#include "ao/core/error.h"
#include "ao/core/texture.h"

namespace ao {

Image<Vec3> shade_for_display(const GBuffer& g, const Image<float>& v, const Image<Vec3>& color) {
  const Vec3 light = normalize(Vec3{-0.4f, 0.8f, 0.45f});  // camera space
  constexpr float kAmbient = 0.45f, kKey = 0.75f, kWrap = 0.5f;
  constexpr float kSkyWithSun = 0.5f;  // La in display units with a direct-light pass
  Image<Vec3> out(g.width(), g.height());
  const auto w = static_cast<std::size_t>(g.width());
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (!g.covered(i)) {
      const float b = display_background(static_cast<int>(i % w), static_cast<int>(i / w));
      out[i] = {b, b, b};
      continue;
    }
    if (!g.direct.empty()) {
      const Vec3 ambient = color.empty() ? g.albedo[i] * v[i] : g.albedo[i] * color[i];  // a V or a W
      out[i] = (ambient + g.direct[i]) * kSkyWithSun;
      continue;
    }
    const float wrap = std::max(0.0f, (dot(g.normal[i], light) + kWrap) / (1.0f + kWrap));
    const float light_in = kAmbient + kKey * wrap;
    out[i] = color.empty() ? g.albedo[i] * (v[i] * light_in) : g.albedo[i] * color[i] * light_in;
  }
  return out;
}

Image<float> with_display_background(const Image<float>& v, const Image<std::uint8_t>& coverage) {
  AO_ASSERT(v.width() == coverage.width() && v.height() == coverage.height());
  Image<float> out = v;
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x)
      if (coverage(x, y) == 0) out(x, y) = display_background(x, y);
  return out;
}

Image<float> visibility_from_ao_map(const GBuffer& g, const Scene& scene, const Image<float>& map, const std::string& map_name) {
  Image<float> v(g.width(), g.height(), 1.0f);
  const std::vector<SceneObject> objects = scene.objects();  // object id - 1 -> mesh
  for (std::size_t i = 0; i < g.object_id.size(); ++i) {
    if (!g.covered(i)) continue;
    const Mesh& mesh = scene.meshes[objects[g.object_id[i] - 1].mesh];
    if (mesh.uvs.empty())
      throw InputError(scene.name + ": mesh '" + mesh.name + "' is visible but has no UVs, so the AO map " + map_name + " cannot be shown on it");
    v[i] = std::clamp(sample_bilinear(map, g.uv[i]), 0.0f, 1.0f);
  }
  return v;
}

}  // namespace ao
