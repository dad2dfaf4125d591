// SPDX-License-Identifier: Apache-2.0
#include "ao/jobs/device.h"

#include <cstdio>

#include <nlohmann/json.hpp>

#include "ao/core/closest_name.h"
#include "ao/core/error.h"
#include "ao/jobs/fields.h"

namespace ao {

const char* to_string(Device device) { return device == Device::Gpu ? "gpu" : "cpu"; }

Device device_from_name(const std::string& name) {
  if (name == "cpu") return Device::Cpu;
  if (name == "gpu") return Device::Gpu;
  throw InputError(field(fields::kDevice) + ": cpu or gpu, got '" + name + "'" + did_you_mean(name, "cpu, gpu"));
}

std::string describe_gpu_passes(std::span<const GpuPassTime> passes) {
  std::string text;
  for (const GpuPassTime& p : passes) {
    char ms[32];
    std::snprintf(ms, sizeof ms, "%.3g", p.ms);
    text += (text.empty() ? "" : ", ") + p.name + " " + ms + " ms";
  }
  return text;
}

nlohmann::json gpu_passes_json(std::span<const GpuPassTime> passes) {
  nlohmann::json out = nlohmann::json::array();
  for (const GpuPassTime& p : passes) out.push_back({{"name", p.name}, {"ms", p.ms}});
  return out;
}

}  // namespace ao
