// SPDX-License-Identifier: Apache-2.0
#include "ao/jobs/compare.h"

#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "ao/core/closest_name.h"
#include "ao/core/error.h"
#include "ao/jobs/fields.h"
#include "ao/jobs/provenance.h"
#include "ao/jobs/compare_gpu_internal.h"
#include "ao/registry/registry.h"
#include "ao/reference/ray_scene.h"

namespace ao {

namespace {

constexpr int kMaxReferenceSpp = 1 << 20;

double elapsed_ms(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
}

std::string fixed(double v, int digits) {
  if (std::isinf(v)) return "inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

// The reference name settings give `method`: its own entry, else the "" entry, else matched.
std::string reference_name(const CompareSettings& s, const std::string& method) {
  if (auto it = s.references.find(method); it != s.references.end()) return it->second;
  if (auto it = s.references.find(""); it != s.references.end()) return it->second;
  return kMatchedReference;
}

nlohmann::json reference_json(const CompareReference& ref, int spp) {
  nlohmann::json j = shortest_floats(ref.spec);
  j["label"] = ref.spec.label();
  j["spp"] = spp;
  j["mean_std_error"] = ref.mean_std_error;
  j["ms"] = ref.ms;
  return j;
}

nlohmann::json metrics_json(const ErrorMetrics& e) {
  return {{"rmse", e.rmse}, {"psnr_db", e.psnr_db}, {"ssim", e.ssim}, {"mean_signed_error", e.mean_signed}, {"max_abs_error", e.max_abs}};
}

// A reference as the table names it: its label and R (and Alchemy's u where it has one).
std::string reference_text(const ReferenceSpec& spec) {
  std::string ref = spec.label() + ", R = " + format_value(shortest_floats(spec.falloff.radius));
  if (spec.kind != ReferenceKind::TangentSphere && spec.falloff.membership == Membership::Alchemy)
    ref += ", u = " + fixed(spec.falloff.effective_alchemy_u(), 4);
  return ref;
}

ProgressFn stage(const CompareSettings& s, const std::string& name) { return s.progress ? s.progress(name) : ProgressFn{}; }

}  // namespace

nlohmann::json shortest_floats(const nlohmann::json& j) {
  if (j.is_object() || j.is_array()) {
    nlohmann::json out = j;
    for (auto& v : out) v = shortest_floats(v);
    return out;
  }
  if (!j.is_number_float()) return j;
  const double d = j.get<double>();
  const float f = static_cast<float>(d);
  if (!std::isfinite(d) || static_cast<double>(f) != d) return j;
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, f);
  double shortest = 0;
  std::from_chars(buf, r.ptr, shortest);
  return shortest;
}

std::string format_value(const nlohmann::json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_float()) {
    const double d = v.get<double>();
    const float f = static_cast<float>(d);
    char buf[32];
    const auto r = std::isfinite(d) && static_cast<double>(f) == d ? std::to_chars(buf, buf + sizeof buf, f, std::chars_format::general)
                                                                   : std::to_chars(buf, buf + sizeof buf, d, std::chars_format::general);
    return std::string(buf, r.ptr);
  }
  return v.dump();
}

CompareSettings resolve_compare_settings(const CompareSettings& in) {
  CompareSettings s = in;
  if (s.spp_reference < 1 || s.spp_reference > kMaxReferenceSpp) throw InputError(field(fields::kCompareSppReference) + " must be in [1, 1048576], got " + std::to_string(s.spp_reference));
  s.falloff.validate();
  if (s.methods.empty()) {
    // Every approximate method (the reference itself is not compared with itself).
    for (const MethodInfo& m : all_methods())
      if (!m.ground_truth) s.methods.emplace_back(m.name);
    if (s.methods.empty()) throw InputError(field(fields::kCompareMethods) + ": the registry has no approximate methods");
  }
  for (const auto& [name, p] : in.params) {
    bool chosen = false;
    for (const std::string& m : s.methods) chosen = chosen || m == name;
    if (!chosen) throw InputError(field(fields::kCompareParams) + ": method '" + name + "' is not among " + field(fields::kCompareMethods));
  }
  s.params.clear();
  for (const std::string& name : s.methods) {
    const MethodInfo& m = find_method(name);
    nlohmann::json p = m.default_params();
    if (auto it = in.params.find(name); it != in.params.end()) {
      if (!it->second.is_object()) throw InputError(field(fields::kCompareParams) + ": parameters of " + name + " must be a JSON object");
      for (const auto& [k, v] : it->second.items()) {
        if (!p.contains(k)) throw InputError(field(fields::kCompareParams) + ": " + name + " has no parameter '" + k + "'" + did_you_mean(k, key_names(p)));
        p[k] = v;
      }
    }
    s.params[name] = shortest_floats(p);
    choose_reference(reference_name(s, name), s.falloff, m.decode(s.params[name]));  // throws for unknown names
  }
  for (const auto& [name, ref] : in.references)
    if (!name.empty() && !s.params.count(name)) throw InputError(field(fields::kCompareReferences) + ": method '" + name + "' is not among " + field(fields::kCompareMethods));
  common_reference_spec(s);  // throws for unknown names
  if (!s.sweep_key.empty()) {
    if (s.sweep_values.empty()) throw InputError(field(fields::kCompareSweep) + ": no values given for '" + s.sweep_key + "'");
    bool any = false;
    std::vector<std::string> keys;  // of every chosen method, for the closest name
    for (const auto& [name, p] : s.params) {
      any = any || p.contains(s.sweep_key);
      for (std::string& k : key_names(p)) keys.push_back(std::move(k));
    }
    if (!any) throw InputError(field(fields::kCompareSweep) + ": no chosen method has a parameter '" + s.sweep_key + "'" + did_you_mean(s.sweep_key, keys));
  }
  return s;
}

std::optional<ReferenceSpec> common_reference_spec(const CompareSettings& s) {
  if (s.common_reference == "none") return std::nullopt;
  const std::optional<ReferenceKind> kind = parse_reference_kind(s.common_reference);
  if (!kind) throw InputError(field(fields::kCompareCommonReference) + ": unknown reference '" + s.common_reference + "' (known: " + reference_kind_names() + ", none)" +
                          did_you_mean(s.common_reference, reference_kind_names() + ", none"));
  switch (*kind) {
    case ReferenceKind::TangentSphere: return ReferenceSpec{ReferenceKind::TangentSphere, {Membership::Cubic, s.falloff.radius}};
    case ReferenceKind::Transfer: return ReferenceSpec{ReferenceKind::Transfer, s.falloff};
    default: return obscurance_reference(s.falloff);
  }
}

CompareResult compare_methods(const RayScene& scene, const GBuffer& g, const AnalyticSurfaces* surfaces, const CompareSettings& settings,
                              GpuDevice* gpu) {
  const CompareSettings s = resolve_compare_settings(settings);
  std::optional<CompareGpuColumn> gpu_column;
  if (s.device == Device::Gpu) gpu_column.emplace(gpu, scene, g);
  CompareResult result;
  result.falloff = s.falloff;
  result.spp_reference = s.spp_reference;
  result.seed = s.seed;
  result.width = g.width();
  result.height = g.height();
  result.sweep_key = s.sweep_key;
  if (gpu_column) result.device = Device::Gpu, result.gl_renderer = gpu_column->renderer(), result.gpu_upload_ms = gpu_column->upload_ms();

  auto reference_for = [&](const ReferenceSpec& spec) -> std::size_t {
    const std::string key = spec.key();
    for (std::size_t i = 0; i < result.references.size(); ++i)
      if (result.references[i].spec.key() == key) return i;
    const auto start = std::chrono::steady_clock::now();
    ReferenceImage img = render_reference(scene, g, spec, {.samples = s.spp_reference}, s.seed + 1, stage(s, "reference (" + spec.label() + ")"));
    result.references.push_back({spec, std::move(img.scalar.visibility), elapsed_ms(start), img.scalar.mean_std_error});
    return result.references.size() - 1;
  };
  auto run_timed = [&](const MethodParams& p, double& ms) {
    const auto start = std::chrono::steady_clock::now();
    MethodOutput out = run_method(MethodInput{g, &scene, s.falloff, s.seed, stage(s, std::string(method_of(p).name)), surfaces}, p);
    ms = elapsed_ms(start);
    return out;
  };

  const Image<std::uint8_t> covered = coverage_mask(g);
  if (const std::optional<ReferenceSpec> common = common_reference_spec(s)) result.common = reference_for(*common);
  auto against_common = [&](const Image<float>& v) {
    return result.common ? compare_images(v, result.references[*result.common].visibility, covered) : ErrorMetrics{};
  };
  for (const std::string& name : s.methods) {
    const MethodInfo& m = find_method(name);
    const MethodParams p = m.decode(s.params.at(name));
    CompareRow row;
    row.method = name;
    row.params = s.params.at(name);
    row.defaults = shortest_floats(m.default_params());
    row.reference = reference_for(choose_reference(reference_name(s, name), s.falloff, p));
    MethodOutput out = run_timed(p, row.ms);
    const Image<float>& ref = result.references[row.reference].visibility;
    row.metrics = compare_images(out.visibility, ref, covered);
    row.heat = signed_error_heat_map(out.visibility, ref, covered, kCompareHeatRange);
    row.common = against_common(out.visibility);
    row.stats = out.stats;
    row.visibility = std::move(out.visibility);
    if (gpu_column) row.gpu = gpu_column->run(p, s.falloff, s.seed, ref, row.visibility, covered, true);
    result.rows.push_back(std::move(row));
  }

  if (!s.sweep_key.empty())
    for (const std::string& name : s.methods) {
      if (!s.params.at(name).contains(s.sweep_key)) continue;
      const MethodInfo& m = find_method(name);
      for (const nlohmann::json& v : s.sweep_values) {
        nlohmann::json j = s.params.at(name);
        j[s.sweep_key] = v;
        const MethodParams p = m.decode(j);
        const std::size_t r = reference_for(choose_reference(reference_name(s, name), s.falloff, p));
        double ms = 0;
        const MethodOutput out = run_timed(p, ms);
        const Image<float>& ref = result.references[r].visibility;
        const ErrorMetrics e = compare_images(out.visibility, ref, covered);
        result.sweep.push_back({name, v, e.rmse, against_common(out.visibility).rmse, ms, {}});
        if (gpu_column) result.sweep.back().gpu = gpu_column->run(p, s.falloff, s.seed, ref, out.visibility, covered, false);
      }
    }
  return result;
}

nlohmann::json compare_table_json(const CompareResult& r) {
  nlohmann::json rows = nlohmann::json::array();
  for (const CompareRow& row : r.rows) {
    const nlohmann::json reference = reference_json(r.references[row.reference], r.spp_reference);
    const ErrorMetrics& e = row.metrics;
    nlohmann::json j = {{"method", row.method}, {"parameters", row.params}, {"ms", row.ms}, {"rmse", e.rmse}, {"psnr_db", e.psnr_db},
                        {"ssim", e.ssim}, {"mean_signed_error", e.mean_signed}, {"max_abs_error", e.max_abs}, {"pixels", e.pixels},
                        {"reference", reference}, {"stats", row.stats}};
    if (r.common) j["common"] = metrics_json(row.common);
    if (row.gpu) j["gpu"] = gpu_run_json(*row.gpu);
    rows.push_back(std::move(j));
  }
  nlohmann::json table = {{"ao", build_info()},      {"width", r.width},        {"height", r.height},
                          {"membership", to_string(r.falloff.membership)}, {"radius", r.falloff.radius},
                          {"seed", r.seed},          {"spp_reference", r.spp_reference}};
  if (r.common) table["common_reference"] = reference_json(r.references[*r.common], r.spp_reference);
  table["rows"] = std::move(rows);
  if (r.device == Device::Gpu) table.update({{"device", "gpu"}, {"gl_renderer", r.gl_renderer}, {"gpu_upload_ms", r.gpu_upload_ms}});
  return shortest_floats(table);
}

namespace {

constexpr std::array<const char*, 5> kMetricTitles{"ms", "RMSE", "PSNR (dB)", "SSIM", "mean signed error"};

// A row's metric cells under kMetricTitles; with the GPU backend each is a pair, CPU then GPU ("-"
// where the GPU did not run the method).
std::vector<std::string> metric_cells(const CompareRow& row) {
  const auto cells = [](double ms, const ErrorMetrics& e) {
    return std::array<std::string, 5>{fixed(ms, 1), fixed(e.rmse, 4), std::isfinite(e.psnr_db) ? fixed(e.psnr_db, 2) : "inf", fixed(e.ssim, 4),
                                      fixed(e.mean_signed, 4)};
  };
  const std::array<std::string, 5> cpu = cells(row.ms, row.metrics);
  std::array<std::string, 5> gpu;
  if (row.gpu) gpu = row.gpu->skipped.empty() ? cells(row.gpu->ms, row.gpu->metrics) : std::array<std::string, 5>{"-", "-", "-", "-", "-"};
  std::vector<std::string> out;
  for (std::size_t i = 0; i < cpu.size(); ++i) {
    out.push_back(cpu[i]);
    if (row.gpu) out.push_back(gpu[i]);
  }
  return out;
}

}  // namespace

std::string compare_table_markdown(const CompareResult& r, const std::string& scene_name) {
  const bool gpu = r.device == Device::Gpu;
  std::ostringstream md;
  md << "# ao compare: " << scene_name << "\n\n"
     << r.width << "x" << r.height << ", R = " << format_value(shortest_floats(r.falloff.radius)) << " ("
     << to_string(r.falloff.membership) << " requested), reference " << r.spp_reference << " rays/pixel, seed " << r.seed
     << ". Errors are over covered pixels, V units; mean signed error > 0: the method is brighter than its reference.";
  if (r.common)
    md << " Each method is judged against the reference of the quantity it estimates (matched); the common columns judge every "
       << "method against one reference, " << reference_text(r.references[*r.common].spec) << ", so that rows can be ranked.";
  md << "\n\n| method | parameters | reference |";
  for (const char* title : kMetricTitles) md << (gpu ? std::string(" ") + title + " cpu | " + title + " gpu |" : std::string(" ") + title + " |");
  md << (r.common ? " RMSE (common) | mean signed (common) |" : "") << "\n|---|---|---|";
  for (std::size_t i = 0; i < kMetricTitles.size() * (gpu ? 2 : 1) + (r.common ? 2 : 0); ++i) md << "---:|";
  md << "\n";
  for (const CompareRow& row : r.rows) {
    std::string params;
    for (const auto& [k, v] : row.params.items()) params += (params.empty() ? "" : ", ") + k + "=" + format_value(v);
    md << "| " << row.method << " | " << params << " | " << reference_text(r.references[row.reference].spec) << " |";
    for (const std::string& cell : metric_cells(row)) md << " " << cell << " |";
    if (r.common) md << " " << fixed(row.common.rmse, 4) << " | " << fixed(row.common.mean_signed, 4) << " |";
    md << "\n";
  }
  if (gpu) {
    md << gpu_markdown_notes(r);
  } else {
    md << "\n`sheet.png`: one row per method in the order above, labelled with its name, its parameters, its reference and its RMSE"
       << (r.common ? " (and against the common reference)" : "") << "; columns: the "
       << "method's V, the reference's V, the signed error (blue: darker than the reference, red: brighter, white: equal, saturated at "
       << "|error| = " << kCompareHeatRange << "; grey checkerboard: background, no surface).\n";
  }
  return md.str();
}

nlohmann::json compare_sweep_json(const CompareResult& r) {
  nlohmann::json rows = nlohmann::json::array();
  for (const SweepRow& s : r.sweep) {
    nlohmann::json row = {{"method", s.method}, {r.sweep_key, s.value}, {"rmse", s.rmse}, {"ms", s.ms}};
    if (r.common) row["rmse_common"] = s.rmse_common;
    if (s.gpu) row["gpu"] = s.gpu->skipped.empty() ? nlohmann::json{{"rmse", s.gpu->metrics.rmse}, {"ms", s.gpu->ms}} : gpu_run_json(*s.gpu);
    rows.push_back(std::move(row));
  }
  return {{"ao", build_info()}, {"key", r.sweep_key}, {"rows", rows}};
}

std::string compare_sweep_markdown(const CompareResult& r) {
  const bool gpu = r.device == Device::Gpu;
  std::ostringstream s;
  s << "# ao compare sweep: " << r.sweep_key << "\n\n| method | " << r.sweep_key << (gpu ? " | RMSE cpu | RMSE gpu |" : " | RMSE |")
    << (r.common ? " RMSE (common) |" : "") << (gpu ? " ms cpu | ms gpu |" : " ms |") << "\n|---|---:|---:|" << (gpu ? "---:|" : "")
    << (r.common ? "---:|" : "") << (gpu ? "---:|---:|" : "---:|") << "\n";
  for (const SweepRow& row : r.sweep) {
    const bool ran = row.gpu && row.gpu->skipped.empty();
    s << "| " << row.method << " | " << format_value(row.value) << " | " << fixed(row.rmse, 4) << " |";
    if (gpu) s << " " << (ran ? fixed(row.gpu->metrics.rmse, 4) : "-") << " |";
    if (r.common) s << " " << fixed(row.rmse_common, 4) << " |";
    s << " " << fixed(row.ms, 1) << " |";
    if (gpu) s << " " << (ran ? fixed(row.gpu->ms, 1) : "-") << " |";
    s << "\n";
  }
  return s.str();
}

std::string compare_key_params(const CompareRow& row, std::size_t max_chars) {
  std::string s;
  for (const auto& [k, v] : row.params.items()) {
    if (k != "samples" && k != "preset" && row.defaults.value(k, nlohmann::json()) == v) continue;
    s += (s.empty() ? "" : ", ") + k + "=" + format_value(v);
  }
  return s.size() <= max_chars ? s : "";
}

}  // namespace ao
