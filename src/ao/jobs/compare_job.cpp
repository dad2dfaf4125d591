// SPDX-License-Identifier: Apache-2.0
// `ao compare` as a library call (compare.h, run_compare): the scene and its G-buffer, the
// comparison, and its table, sheet and sweep written as one transaction. docs/compare.md.
#include <cstdio>
#include <fstream>

#include "ao/core/error.h"
#include "ao/core/memory.h"
#include "ao/jobs/fields.h"
#include "ao/core/stopwatch.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/io/atomic_file.h"
#include "ao/io/image_io.h"
#include "ao/io/output_set.h"
#include "ao/io/text.h"
#include "ao/jobs/compare.h"
#include "ao/jobs/contact_sheet.h"
#include "ao/reference/ray_scene.h"
#include "ao/registry/registry.h"

namespace ao {

namespace {

namespace fs = std::filesystem;

std::string fixed4(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4f", v);
  return buf;
}

void write_text(const fs::path& path, const std::string& text) { write_bytes_atomically(path, text); }

// The sheet's columns: the method's V, its reference's V and the heat map; with the GPU backend
// the method's V and heat map once per backend. Titles are pieces wrapped between, never inside,
// so "too bright" stays whole; red above zero and blue below, as signed_error_colour draws them.
std::vector<SheetColumn> sheet_columns(bool gpu) {
  const SheetColumn heat{{"signed error", "(red: too bright", "/ blue: too dark)"}, true};
  if (!gpu) return {{{"method"}}, {{"ray-traced", "reference"}}, heat};
  return {{{"method", "(cpu)"}}, {{"method", "(gpu)"}}, {{"ray-traced", "reference"}}, {{"signed error", "(cpu)"}, true}, {{"signed error", "(gpu)"}, true}};
}

// A row's cells under sheet_columns; the GPU's are empty where it did not run the method.
std::vector<SheetCell> sheet_cells(const CompareResult& result, const CompareRow& row) {
  const Image<float>* reference = &result.references[row.reference].visibility;
  if (result.device != Device::Gpu) return {{&row.visibility}, {reference}, {nullptr, &row.heat}};
  const bool ran = row.gpu && row.gpu->skipped.empty();
  return {{&row.visibility}, {ran ? &row.gpu->visibility : nullptr}, {reference}, {nullptr, &row.heat}, {nullptr, ran ? &row.gpu->heat : nullptr}};
}

// The sheet, labelled, the background (coverage 0) marked. A missing font costs the labels, never
// the comparison.
Image<Vec3> make_sheet(const CompareResult& result, const Image<std::uint8_t>& coverage, const fs::path& font_path, const JobReporter& reporter) {
  std::vector<SheetRow> rows;
  for (const CompareRow& row : result.rows) {
    std::vector<std::string> label = {row.method};
    const std::string kp = compare_key_params(row);
    if (!kp.empty()) label.push_back(kp);
    label.push_back("reference: " + result.references[row.reference].spec.label());
    label.push_back("RMSE " + fixed4(row.metrics.rmse));  // as in table.md
    if (row.gpu && row.gpu->skipped.empty()) label.back() = "RMSE cpu " + fixed4(row.metrics.rmse) + ", gpu " + fixed4(row.gpu->metrics.rmse);
    if (result.common && *result.common != row.reference)
      label.push_back("vs " + result.references[*result.common].spec.label() + ": " + fixed4(row.common.rmse));
    rows.push_back({sheet_cells(result, row), std::move(label), &coverage});
  }
  std::string font_error;
  const std::optional<Font> font = Font::open(font_path.empty() ? fs::path(kDejaVuSansPath) : font_path, &font_error);
  if (!font) reporter.warn(font_error + "; sheet.png has no labels (install fonts-dejavu-core or set AO_FONT)");
  return contact_sheet(sheet_columns(result.device == Device::Gpu), rows, kCompareHeatRange, font ? &*font : nullptr);
}

std::vector<std::string> output_files(bool sweep) {
  std::vector<std::string> files = {"table.json", "table.md", "sheet.png"};
  if (sweep) files.insert(files.end(), {"sweep.json", "sweep.md"});
  return files;
}

void write_outputs(OutputSet& outputs, const fs::path& dir, CompareJobResult& out) {
  auto text = [&](const std::string& name, const std::string& content) {
    outputs.write(dir / name, [&] { write_text(dir / name, content); });
  };
  text("table.json", out.table.dump(2) + "\n");
  text("table.md", out.markdown);
  outputs.write(dir / "sheet.png", [&] { write_rgb_image(dir / "sheet.png", out.sheet); });
  if (!out.result.sweep_key.empty()) {
    text("sweep.json", compare_sweep_json(out.result).dump(2) + "\n");
    text("sweep.md", compare_sweep_markdown(out.result));
  }
  outputs.commit();
  for (const std::string& f : output_files(!out.result.sweep_key.empty())) out.written.push_back(dir / f);
}

}  // namespace

namespace {

// The images of the run against the memory available, before the scene is loaded: methods and
// references at their largest count (one reference per method, and the common one), and the
// largest method scratch of the registry counted once (estimate_compare_memory) plus the methods'
// own extra memory.
void check_compare_memory(const CompareRequest& request, const CompareSettings& settings) {
  const int width = request.camera.width.value_or(request.camera.default_width), height = request.camera.height.value_or(request.camera.default_height);
  const int methods = static_cast<int>(settings.methods.size());
  std::uint64_t extra = 0;
  for (const std::string& name : settings.methods) {
    const MethodInfo& m = find_method(name);
    const auto it = settings.params.find(name);
    extra = std::max(extra, extra_memory(m.decode(it != settings.params.end() ? it->second : nlohmann::json::object())).bytes);
  }
  const std::uint64_t bytes = estimate_compare_memory({.width = width, .height = height, .methods = methods, .references = methods + 1,
                                                        .sheet_columns = static_cast<int>(sheet_columns(settings.device == Device::Gpu).size())}) + extra;
  check_memory(bytes, "ao compare: " + std::to_string(methods) + (methods == 1 ? " method at " : " methods at ") + std::to_string(width) + "x" + std::to_string(height) + " pixels");
}

}  // namespace

fs::path default_compare_dir(const CompareRequest& request) { return "compare-" + fs::path(request.scene.name()).stem().string(); }

CompareJobResult run_compare(const CompareRequest& request, const JobReporter& reporter) {
  // Everything that can be checked without rendering is checked before anything is written.
  CompareSettings settings = resolve_compare_settings(request.settings);  // R is set below; the check uses the default falloff
  request.camera.validate();
  request.falloff.validate();
  OutputSet outputs;
  request.scene.declare_inputs(outputs);
  if (!request.out_dir.empty()) {
    outputs.add_directory(request.out_dir, field(fields::kCompareOutDir));
    for (const std::string& f : output_files(!settings.sweep_key.empty())) outputs.add_output(request.out_dir / f, field(fields::kCompareOutDir));
  }

  check_compare_memory(request, settings);
  Stopwatch clock;
  std::optional<GpuDevice> gpu;
  if (settings.device == Device::Gpu) gpu = GpuDevice::open();  // before anything is loaded: without a usable OpenGL the run stops here
  const std::shared_ptr<const Scene> scene = request.scene.load();
  for (const std::string& w : scene->warnings) reporter.warn(w);
  const RayScene rays(*scene);
  CompareJobResult out;
  out.camera = choose_camera(*scene, request.camera);
  const GBuffer g = render_gbuffer(rays, out.camera, GBufferOptions{.normal = request.normal}, reporter.start("G-buffer"));
  settings.falloff = choose_falloff(request.falloff, interest_diagonal(*scene));
  const double setup_ms = clock.lap_ms();

  settings.progress = reporter.stage;
  out.result = compare_methods(rays, g, &scene->analytic, settings, gpu ? &*gpu : nullptr);
  // Methods report problems they worked around (e.g. cone: open meshes).
  for (const CompareRow& row : out.result.rows)
    if (row.stats.contains("warnings"))
      for (const auto& w : row.stats["warnings"]) {
        const std::string text = w.get<std::string>(), prefix = row.method + ": ";
        reporter.warn(text.rfind(prefix, 0) == 0 ? text : prefix + text);  // named once
      }
  out.scene = scene->name;
  out.table = compare_table_json(out.result);
  out.table["scene"] = scene->name;
  const Camera& c = g.camera;
  out.table["camera"] = {{"eye", {c.eye.x, c.eye.y, c.eye.z}}, {"target", {c.target.x, c.target.y, c.target.z}}, {"up", {c.up.x, c.up.y, c.up.z}},
                         {"fov", c.vertical_fov_deg}};
  out.table["setup_ms"] = setup_ms;
  out.markdown = compare_table_markdown(out.result, scene->name);
  out.sheet = make_sheet(out.result, coverage_mask(g), request.font, reporter);
  if (!request.out_dir.empty()) write_outputs(outputs, request.out_dir, out);
  return out;
}

}  // namespace ao
