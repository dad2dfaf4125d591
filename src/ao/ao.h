// SPDX-License-Identifier: Apache-2.0
// ao: ambient occlusion on the CPU. The one header a program includes; it names every public
// header of the library (every installed header but this one: examples/check_install.sh checks),
// grouped as the README's layout. Link ao::ao (CMake: find_package(ao 0.2),
// or pkg-config ao); a program that needs only the G-buffer and in-memory-scene parts (core, scene,
// methods but the registry, eval) may include those headers alone and link ao::core.
//
// The job calls do what the ao command does, with its defaults: run_render (jobs/render.h),
// run_bake (jobs/bake.h), compare and tune (jobs/compare.h, jobs/tune.h). A minimal program at the
// level below them (examples/ has complete ones; README "Use it as a library"):
//   const ao::Scene scene = ao::load_scene_file("bunny.obj");
//   const ao::RayScene rays(scene);
//   const ao::GBuffer g = ao::render_gbuffer(rays, ao::frame_bounds(scene.bounds(), {0.55f, 0.5f, 1}, 40, 640, 360));
//   const ao::MethodParams p = ao::find_method("volumetric").decode({{"samples", 16}});
//   const ao::MethodOutput out = ao::run_method({g, &rays, {ao::Membership::Step, 0.1f * scene.bounds().diagonal()}, 1}, p);
//   ao::write_image("ao.exr", out.visibility);
#pragma once

#include "ao/version.h"

// core: math, affine maps, images, G-buffers, cameras, sampling, membership functions, parallel
// tiles, parameter tables, JSON values held by pointer, memory estimates, stopwatch, errors and the closest name they suggest.
#include "ao/core/affine.h"
#include "ao/core/camera.h"
#include "ao/core/closest_name.h"
#include "ao/core/color_shared.h"
#include "ao/core/error.h"
#include "ao/core/hash_shared.h"
#include "ao/core/gbuffer.h"
#include "ao/core/image.h"
#include "ao/core/json_value.h"
#include "ao/core/math.h"
#include "ao/core/membership.h"
#include "ao/core/memory.h"
#include "ao/core/parallel.h"
#include "ao/core/params.h"
#include "ao/core/params_table.h"
#include "ao/core/progress.h"
#include "ao/core/sampling.h"
#include "ao/core/shared.h"  // the prelude of the *_shared.h headers, which C++ and the GPU shaders both read
#include "ao/core/stopwatch.h"
#include "ao/core/texture.h"
#include "ao/core/typed_slots.h"
#include "ao/simd/depth_plane.h"
#include "ao/simd/target.h"  // which SIMD instruction set the kernels run with

// scene: meshes, scenes, built-in and analytic scenes, and what a mesh's connectivity says.
#include "ao/scene/analytic.h"
#include "ao/scene/mesh.h"
#include "ao/scene/procedural.h"
#include "ao/scene/topology.h"

// The ray-traced ground truth and the scene -> G-buffer pass (Embree stays behind RayScene).
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/reference/direct_light.h"
#include "ao/reference/ray_offset.h"
#include "ao/reference/ray_scene.h"
#include "ao/reference/raytraced.h"
#include "ao/reference/raytraced_method.h"
#include "ao/reference/reference.h"
#include "ao/reference/tangent_sphere.h"
#include "ao/reference/transfer_reference.h"

// methods: one paper per header, and the registry that runs any of them by name.
#include "ao/methods/alchemy/alchemy.h"
#include "ao/methods/alchemy/alchemy_shared.h"
#include "ao/methods/filters/bilateral.h"
#include "ao/methods/characteristic.h"
#include "ao/methods/cone/cone.h"
#include "ao/methods/cone/cone_shared.h"
#include "ao/methods/cone/mesh_closure.h"
#include "ao/methods/containment/containment.h"
#include "ao/methods/depth_layers.h"
#include "ao/methods/gtao/gtao.h"
#include "ao/methods/gtao/gtao_shared.h"
#include "ao/methods/filters/interleave.h"
#include "ao/methods/method.h"
#include "ao/registry/registry.h"
#include "ao/methods/samples.h"
#include "ao/methods/screen_space_shared.h"
#include "ao/methods/transfer/transfer.h"
#include "ao/methods/volumetric/volumetric.h"
#include "ao/methods/cone/voxelize.h"
#include "ao/methods/cone/winding_number.h"

// bake: AO maps (outside-in histogram, inside-out ray-traced), denoising, padding, per-vertex AO,
// high to low, bake groups, UDIM tiles, MikkTSpace tangent frames.
#include "ao/bake/bake_groups.h"
#include "ao/bake/bake_result.h"
#include "ao/bake/denoise.h"
#include "ao/bake/high_to_low.h"
#include "ao/bake/histogram.h"
#include "ao/bake/ortho_raster.h"
#include "ao/bake/padding.h"
#include "ao/bake/per_vertex.h"
#include "ao/bake/raytraced_bake.h"
#include "ao/bake/sphere_directions.h"
#include "ao/bake/tangents.h"
#include "ao/bake/texel_coverage.h"
#include "ao/bake/udim.h"

// gpu: the methods as OpenGL compute shaders (docs/gpu.md); without AO_GPU, opening a device says so.
#include "ao/gpu/device.h"
#include "ao/gpu/gbuffer.h"
#include "ao/registry/methods_gpu.h"
#include "ao/methods/cone/voxelize_gpu.h"

// eval: error metrics against a reference, display shading.
#include "ao/eval/metrics.h"
#include "ao/eval/shading.h"

// io: mesh and image files (and the checks run before assimp reads them), G-buffer EXR passes,
// camera files, glTF and PLY export, glTF round trips, atomic writes and output sets, text.
#include "ao/io/asset_path.h"
#include "ao/io/atomic_file.h"
#include "ao/io/camera_json.h"
#include "ao/io/commit_journal.h"
#include "ao/io/gbuffer_exr.h"
#include "ao/io/gltf_check.h"
#include "ao/io/gltf_document.h"
#include "ao/io/gltf_export.h"
#include "ao/io/image_io.h"
#include "ao/io/json_text.h"
#include "ao/io/mesh_io.h"
#include "ao/io/number_text.h"
#include "ao/io/obj_check.h"
#include "ao/io/obj_reader.h"
#include "ao/io/off_reader.h"
#include "ao/io/output_set.h"
#include "ao/io/ply_export.h"
#include "ao/io/ply_reader.h"
#include "ao/io/stl_check.h"
#include "ao/io/text.h"

// jobs: render, bake, compare and tune as library calls, with the ao command's defaults; what
// every job starts from (scene, camera, falloff), frame-after-frame rendering, progress reports;
// AO at given points; the request fields errors name; the provenance records of outputs; one view
// of a prepared scene (render_view.h: what the viewer runs per frame).
#include "ao/jobs/bake.h"
#include "ao/jobs/compare.h"
#include "ao/jobs/contact_sheet.h"
#include "ao/jobs/device.h"
#include "ao/jobs/fields.h"
#include "ao/jobs/frames.h"
#include "ao/jobs/inputs.h"
#include "ao/jobs/points.h"
#include "ao/jobs/progress_meter.h"
#include "ao/jobs/provenance.h"
#include "ao/jobs/render.h"
#include "ao/jobs/render_view.h"
#include "ao/jobs/reporter.h"
#include "ao/jobs/tune.h"
