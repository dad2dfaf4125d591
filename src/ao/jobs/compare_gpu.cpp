// SPDX-License-Identifier: Apache-2.0
#include "ao/jobs/compare_gpu_internal.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "ao/core/error.h"
#include "ao/registry/methods_gpu.h"
#include "ao/reference/ray_scene.h"

namespace ao {

namespace {

GpuDevice& device_or_open(GpuDevice* given, std::optional<GpuDevice>& own) {
  if (given) return *given;
  return own.emplace(GpuDevice::open());
}

double max_abs_difference(const Image<float>& a, const Image<float>& b, const Image<std::uint8_t>& covered) {
  double worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (covered[i]) worst = std::max(worst, std::abs(static_cast<double>(a[i]) - b[i]));
  return worst;
}

}  // namespace

CompareGpuColumn::CompareGpuColumn(GpuDevice* device, const RayScene& scene, const GBuffer& gbuffer)
    : device_(device_or_open(device, own_)), scene_(scene), gbuffer_(GpuGBuffer::upload(device_, gbuffer)) {}

double CompareGpuColumn::upload_ms() const {
  double ms = 0;
  for (const GpuPassTime& p : gbuffer_.passes()) ms += p.ms;
  return ms;
}

CompareGpuRun CompareGpuColumn::run(const MethodParams& params, const Falloff& falloff, std::uint32_t seed,
                                    const Image<float>& reference, const Image<float>& cpu, const Image<std::uint8_t>& covered, bool keep_images) {
  CompareGpuRun out;
  try {
    check_gpu_method(params);
    if (method_of(params).needs_scene && !gpu_scene_) gpu_scene_ = GpuScene::upload(device_, scene_.scene());
    const auto start = std::chrono::steady_clock::now();
    GpuMethodOutput g = run_gpu_method(device_, GpuMethodInput{gbuffer_, gpu_scene_ ? &*gpu_scene_ : nullptr, falloff, seed}, params);
    out.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    out.passes = std::move(g.passes);
    out.stats = std::move(g.output.stats);
    out.metrics = compare_images(g.output.visibility, reference, covered);
    out.max_abs_difference = max_abs_difference(g.output.visibility, cpu, covered);
    if (keep_images) {
      out.heat = signed_error_heat_map(g.output.visibility, reference, covered, kCompareHeatRange);
      out.visibility = std::move(g.output.visibility);
    }
  } catch (const InputError& e) {
    out = CompareGpuRun{};
    out.skipped = e.what();
  }
  return out;
}

nlohmann::json gpu_run_json(const CompareGpuRun& run) {
  if (!run.skipped.empty()) return {{"skipped", run.skipped}};
  const ErrorMetrics& e = run.metrics;
  return {{"ms", run.ms},
          {"rmse", e.rmse},
          {"psnr_db", e.psnr_db},
          {"ssim", e.ssim},
          {"mean_signed_error", e.mean_signed},
          {"max_abs_error", e.max_abs},
          {"pixels", e.pixels},
          {"max_abs_difference_from_cpu", run.max_abs_difference},
          {"passes", gpu_passes_json(run.passes)},
          {"stats", run.stats}};
}

std::string gpu_markdown_notes(const CompareResult& r) {
  std::ostringstream md;
  md << "\nGPU: " << r.gl_renderer << ", on the G-buffer above uploaded once (" << describe_gpu_passes(r.gpu_upload_ms > 0 ? std::vector<GpuPassTime>{{"upload", r.gpu_upload_ms}} : std::vector<GpuPassTime>{})
     << "). \"ms gpu\" is the whole call, the passes and reading the images back; each pass's GPU time is in table.json (rows[].gpu.passes).";
  if (r.gl_renderer.find("llvmpipe") != std::string::npos || r.gl_renderer.find("softpipe") != std::string::npos)
    md << " This renderer is Mesa's software one: its times are the CPU's, not a GPU's.";
  md << "\n";
  for (const CompareRow& row : r.rows)
    if (row.gpu && !row.gpu->skipped.empty()) md << "\nNot run on the GPU: " << row.method << ": " << row.gpu->skipped << "\n";
  md << "\n`sheet.png`: one row per method in the order above, labelled with its name, its reference and its RMSE on each backend; "
     << "columns: the method's V on the CPU and on the GPU, the reference's V, the signed error of each (blue: darker than the "
     << "reference, red: brighter, white: equal, saturated at |error| = " << kCompareHeatRange << "; grey: background; empty where the "
     << "GPU did not run the method).\n";
  return md.str();
}

}  // namespace ao
