// SPDX-License-Identifier: Apache-2.0
// What every method reads and returns, on the CPU and on the GPU: the interface between a method's
// folder (methods/<name>/: its parameters, host code, kernel, shaders) and its callers (the
// registry, which holds the one table of methods, and through it the jobs, the viewer and Python).
// A method's entry points are overloads on its own parameter struct:
//
//   MethodOutput run(const MethodInput& in, const ContainmentParams& params);        // the CPU
//   MethodOutput run_gpu(gpu_detail::Run& r, const GpuMethodInput& in, const ContainmentParams& p);  // the GPU, where it has one
//
// and the registry's MethodParams (a variant of those structs, decoded once from JSON, `-p` or
// Python keywords by each method's table) reaches them by std::visit, so a typed parameter can be
// followed from the request to the kernel.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/image.h"
#include "ao/core/json_value.h"
#include "ao/core/membership.h"
#include "ao/core/progress.h"
#include "ao/core/typed_slots.h"
#include "ao/gpu/device.h"
#include "ao/gpu/gbuffer.h"
#include "ao/scene/analytic.h"
#include "ao/scene/mesh.h"

namespace ao {

class RayScene;

/// What methods keep between calls on one scene, for a caller that renders frame after frame (a
/// viewer, a benchmark): cone's mesh closure and voxel grid, transfer's scratch images. A method's
/// output is the same with and without it. The caller owns it and passes it with every call on the
/// same scene; a method starts over when handed another Scene object. Not for concurrent calls.
class MethodCache {
 public:
  /// The method's T, made by `make()` on first use and again when `fresh(const T&)` is false.
  template <class T, class Make, class Fresh>
  T& get(Make&& make, Fresh&& fresh) {
    return slots_.get<T>(std::forward<Make>(make), std::forward<Fresh>(fresh));
  }

 private:
  TypedSlots slots_;
};

/// Everything a method may read. Screen-space methods read only the G-buffer (and, when asked for
/// an analytic characteristic function, the scene's analytic description); object-space methods
/// (the ray-traced reference, cone) also need the scene, which is absent when the G-buffer came
/// from a file.
struct MethodInput {
  const GBuffer& gbuffer;
  /// The scene as Embree traces it (reference/ray_scene.h), for the ray-traced reference; null when
  /// running from a G-buffer file. The registry's run_method derives `scene` and
  /// `trace_second_layer` from it when they are left unset.
  const RayScene* rays = nullptr;
  Falloff falloff;                  ///< R and membership; methods that imply their own say so.
  std::uint32_t seed = 0;           ///< Keys every per-pixel sample set.
  ProgressFn progress;
  /// The scene's analytic surfaces (Scene::analytic, world space; the G-buffer's camera takes them
  /// to camera space). Null when running from a G-buffer file; may be set and empty.
  const AnalyticSurfaces* surfaces = nullptr;
  /// Null, or what the methods keep between calls on this scene (MethodCache).
  MethodCache* cache = nullptr;
  /// The scene, for methods that voxelize it (cone); null when running from a G-buffer file.
  const Scene* scene = nullptr;
  /// The second depth layer of `gbuffer` at a separation (world units), traced in the scene for a
  /// method asked for two layers when the G-buffer holds none (gbuffer/render_gbuffer.h:
  /// render_second_layer_depth); empty when there is no scene to trace.
  std::function<Image<float>(float separation)> trace_second_layer;
};

struct MethodOutput {
  /// V in [0,1] per pixel; 1 where the G-buffer is not covered. (Transfer's radiance mode: the
  /// luminance of W, which exceeds 1 where sunlit occluders send more light than the sky.)
  Image<float> visibility;
  Image<Vec3> color;  ///< Optional RGB result (e.g. ambient transfer's W per channel); empty if none.
  /// Further outputs by name, each one of the method's MethodInfo::extras (e.g. "obscurance").
  std::map<std::string, Image<float>> extras;
  /// The ray-traced ground truth: the standard error of V per pixel (0 where not covered); empty
  /// for the other methods. Not written by `ao render`; the Python module returns it.
  Image<float> std_error;
  JsonValue stats;  ///< Method-specific numbers for --json (rays, standard errors, ...), as a JSON object or null.
};

/// Memory a method needs beyond its images, for the check before a run (core/memory.h).
struct MethodMemory {
  std::uint64_t bytes = 0;
  std::string what;  ///< For the message: "a 512^2 x 256 voxel grid".
};

/// What a GPU method reads: the G-buffer on the device, and for cone (which voxelizes the scene)
/// the scene on the same device.
struct GpuMethodInput {
  const GpuGBuffer& gbuffer;
  const GpuScene* scene = nullptr;  ///< cone only; null otherwise.
  Falloff falloff;                  ///< R and membership, as MethodInput::falloff.
  std::uint32_t seed = 0;           ///< Keys the sample rotations and jitter, as MethodInput::seed.
};

/// A GPU method's result.
struct GpuMethodOutput {
  /// As the CPU method returns it (visibility, color, extras: transfer's W and obscurance, alchemy's
  /// unfiltered V, gtao's multi-bounce colour), with `stats` extended by "device" (the GL renderer)
  /// and "gpu_ms" (pass name -> milliseconds).
  MethodOutput output;
  std::vector<GpuPassTime> passes;  ///< GPU time of each pass, in the order they ran.
  std::string renderer;             ///< GL_RENDERER of the device that ran it.
};

}  // namespace ao
