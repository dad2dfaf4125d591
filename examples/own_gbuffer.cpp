// SPDX-License-Identifier: Apache-2.0
// AO from your own depth and normal buffers (a compositor's passes, another renderer's G-buffer),
// with volumetric AO. Links ao::core only: no Embree, no file formats. Here the "renderer" is a
// floor with a box standing on it, written straight into the buffers; writes the result as PGM.
#include <cstdio>
#include <fstream>

#include <ao/core/gbuffer.h>
#include <ao/methods/volumetric/volumetric.h>

int main() {
  // 1. The camera the buffers were rendered with: its field of view and size (camera space looks down -z).
  ao::Camera camera;
  camera.vertical_fov_deg = 60.0f, camera.width = 320, camera.height = 240;
  ao::GBuffer g(camera);
  // 2. Fill the buffers: per pixel the camera-space position (its -z is the linear depth), unit
  //    normal, and an object id >= 1 (0 marks background).
  //    The view looks straight down at a floor 2 units away; a 0.5-unit-high box stands in the middle.
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const bool box = x > 130 && x < 190 && y > 90 && y < 150;
      const float depth = box ? 1.5f : 2.0f;
      const ao::Vec3 ray = camera.camera_direction(x + 0.5f, y + 0.5f);  // z = -1
      g.position(x, y) = ray * depth;
      g.normal(x, y) = {0, 0, 1}, g.albedo(x, y) = {0.8f, 0.8f, 0.8f}, g.object_id(x, y) = 1;
    }
  // 3. Volumetric AO (tangent sphere of radius R/2) with R = 0.4 world units and default parameters.
  const ao::Image<float> v = ao::volumetric_ao(g, 0.4f, ao::VolumetricParams{}, /*seed=*/1);
  // 4. Write V as an 8-bit PGM: the floor darkens along the box's foot.
  std::ofstream out("own_gbuffer.pgm", std::ios::binary);
  out << "P5\n" << v.width() << ' ' << v.height() << "\n255\n";
  for (std::size_t i = 0; i < v.size(); ++i) out.put(static_cast<char>(v[i] * 255.0f + 0.5f));
  std::printf("own_gbuffer: V at the box's foot %.2f, open floor %.2f\n", v(125, 120), v(20, 20));
  return out ? 0 : 1;
}
