// SPDX-License-Identifier: Apache-2.0
#include "view/state.h"

#include "ao/registry/registry.h"

namespace ao::view {

nlohmann::json& ViewerState::params() {
  auto it = params_by_method.find(method);
  if (it == params_by_method.end()) it = params_by_method.emplace(method, find_method(method).default_params()).first;
  return it->second;
}

void ViewerState::select_method(const std::string& name) {
  method = name;
  params();
  dirty_method = true;
}

void ViewerState::set_view(ViewMode v) {
  view = v;
  dirty_display = true;
}

void ViewerState::camera_moved() {
  moved = true;
  dirty_gbuffer = true;
}

}  // namespace ao::view
