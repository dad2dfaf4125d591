// SPDX-License-Identifier: Apache-2.0
// `ao render` as a library call: a scene (or a G-buffer) and a method in, the AO image, the
// G-buffer, the method's other outputs and a summary out, and the files asked for written as one
// transaction. The command line, the viewer and the Python module all render through here.
//
//   RenderRequest r;
//   r.scene.args = {"mesh.obj"};
//   r.method = "volumetric";
//   r.outputs.visibility = "ao.png";
//   RenderResult out = run_render(r);   // out.output.visibility: V per pixel
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/json_value.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/gpu/device.h"
#include "ao/jobs/device.h"
#include "ao/jobs/inputs.h"
#include "ao/jobs/reporter.h"
#include "ao/methods/method.h"
#include "ao/reference/direct_light.h"

namespace ao {

/// The files a render writes; an empty path is not written.
struct RenderOutputs {
  std::filesystem::path visibility;  ///< V: .png (linear, png_bits), .exr (float), .tif, .tga, .jpg.
  std::filesystem::path shaded;      ///< A picture for people (shade_for_display), sRGB.
  std::filesystem::path gbuffer;     ///< The G-buffer as a multi-channel EXR (docs/gbuffer.md).
  /// The method's extra outputs (MethodInfo::extras) beside `visibility`, as <stem>-<name><ext>.
  bool extras = false;
  int png_bits = 8;  ///< 8 or 16.
  /// Also write each output's record beside it, <output>.ao.json (jobs/provenance.h): ao's version,
  /// the inputs' SHA-256, every setting; in the same transaction, renamed after the outputs.
  bool provenance = false;
};

struct RenderRequest {
  SceneSource scene;
  /// A G-buffer EXR to read instead of rendering a scene (screen-space methods only).
  std::filesystem::path gbuffer_file;
  /// The caller's own G-buffer instead of a scene (screen-space methods only); wins over gbuffer_file.
  std::shared_ptr<const GBuffer> gbuffer;
  std::string method = "raytraced";  ///< A registry name (all_methods()).
  JsonValue params = JsonValue::object();  ///< Overrides of the method's parameters (its table's names), a JSON object.
  std::optional<int> samples;          ///< Sets the method's MethodInfo::samples_param.
  std::optional<float> target_error;   ///< Sets the method's MethodInfo::target_error_param.
  CameraRequest camera;                ///< 1280 x 720 unless given.
  FalloffRequest falloff;
  std::optional<SurfaceNormal> normal; ///< The G-buffer's N (default shading); not with a G-buffer input.
  std::uint32_t seed = 1;              ///< Keys every per-pixel sample set.
  /// Where the method runs (default the CPU). Gpu: a headless device (GpuDevice::open: the first
  /// hardware EGL device, else Mesa's llvmpipe) runs it on this render's G-buffer, uploaded, so the
  /// image is the CPU's up to float rounding; SystemError when there is no usable OpenGL 4.3.
  Device device = Device::Cpu;
  std::optional<Sun> sun;              ///< A direct-light pass (read by --shaded and transfer's radiance mode).
  std::filesystem::path ao_map;        ///< Show this baked AO map on the scene instead of running a method.
  bool shade = false;                  ///< Make the shaded picture even when outputs.shaded is empty.
  RenderOutputs outputs;
};

struct RenderResult {
  std::string scene;        ///< Its name (the G-buffer file's path for a G-buffer input).
  std::string method;       ///< The registry name, or "ao-map".
  JsonValue params;         ///< Complete (the table's canonical form); empty object for ao-map.
  Falloff falloff;
  std::string normal;       ///< "shading", "geometric", or "file" for a G-buffer input.
  GBuffer gbuffer;
  MethodOutput output;
  Image<Vec3> shaded;       ///< When asked for (RenderRequest::shade or outputs.shaded).
  std::map<std::string, std::filesystem::path> extras_written;  ///< Extra name -> file.
  std::size_t covered_pixels = 0;
  double mean_visibility = 1.0;  ///< Over covered pixels.
  double method_ms = 0;          ///< The method's run time (on the GPU: the upload, the passes and reading the images back).
  Device device = Device::Cpu;   ///< Where the method ran.
  std::string gl_renderer;       ///< GL_RENDERER of the GPU device ("llvmpipe (LLVM 15.0.6, 256 bits)"); empty on the CPU.
  std::vector<GpuPassTime> gpu_passes;  ///< GPU time of each pass in the order they ran (upload, the method's); empty on the CPU.
  JsonValue summary;             ///< What `ao render --json` prints (parameters, timings, rays/s, ...).
};

/// The checks that need no file: the method, its parameters, the camera, the falloff, the output
/// names and the combination of options. InputError with one line naming the problem.
void check_render_request(const RenderRequest& request);

/// The provenance record (jobs/provenance.h) of what `request` writes, without the per-file
/// "output": the scene's files, the camera file, the G-buffer and AO map files as inputs (hashed
/// when `hash_inputs`; otherwise each input has its role and path only), and as settings every
/// field that changes an output (the method and its complete parameters, the camera and falloff
/// as requested, normal, seed, device, sun, PNG bits, which outputs). Checks the request first
/// (check_render_request).
nlohmann::json render_provenance(const RenderRequest& request, bool hash_inputs = true);

/// `<scene stem>-<method>.png`, the name `ao render` writes without -o.
std::filesystem::path default_render_output(const RenderRequest& request);

/// Renders `request`: checks it (check_render_request), declares every output against every input
/// (InputError before any work when one names another), checks memory, loads, renders the
/// G-buffer and the method, and writes the outputs asked for together at the end.
RenderResult run_render(const RenderRequest& request, const JobReporter& reporter = {});

}  // namespace ao
