// Ambient occlusion of a mesh file, written as a float EXR image: the shortest complete use of the
// library. Usage: mesh_to_exr MESH [OUT.exr] [METHOD]   (METHOD: raytraced, volumetric, cone, ...)
#include <cstdio>
#include <exception>

#include <ao/ao.h>

int main(int argc, char** argv) try {
  if (argc < 2) return std::fprintf(stderr, "usage: %s MESH [OUT.exr] [METHOD]\n", argv[0]), 2;
  // 1. Load the mesh (OBJ, PLY, OFF, STL, glTF) into a Scene; bad files throw ao::InputError.
  const ao::Scene scene = ao::load_scene_file(argv[1]);
  // 2. Build the ray-tracing structure (Embree, hidden behind RayScene).
  const ao::RayScene rays(scene);
  // 3. A camera that frames the scene from the front right and above, 640x360 pixels.
  const ao::Camera camera = ao::frame_bounds(scene.bounds(), {0.55f, 0.5f, 1.0f}, 40.0f, 640, 360);
  // 4. The G-buffer: camera-space position, depth, normal, albedo per pixel, by primary rays.
  const ao::GBuffer gbuffer = ao::render_gbuffer(rays, camera);
  // 5. Classical AO (step membership) within R = 10% of the scene's diagonal.
  const ao::Falloff falloff{ao::Membership::Step, 0.1f * scene.bounds().diagonal()};
  // 6. Any method of the registry by name, with its default parameters (a JSON object).
  const ao::MethodInfo& method = ao::find_method(argc > 3 ? argv[3] : "raytraced");
  const ao::MethodOutput out = method.run({gbuffer, &rays, falloff, /*seed=*/1}, method.default_params());
  // 7. Write V in [0, 1] (1 = open) as a float EXR; the write is atomic.
  ao::write_image(argc > 2 ? argv[2] : "ao.exr", out.visibility);
  std::printf("%s: %dx%d, method %s, AO written\n", scene.name.c_str(), gbuffer.width(), gbuffer.height(), method.name.data());
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "mesh_to_exr: %s\n", e.what());
  return 1;
}
