// SPDX-License-Identifier: Apache-2.0
// `ao view`: the methods live in a window (GLFW 3.3, OpenGL 3.3 core, Dear ImGui), beside a
// ray-traced reference that accumulates while the camera is still. The library's job layer does the
// work (FrameRenderer: G-buffer and method; the references; metrics); this folder only shows it and
// turns input into calls.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/camera.h"
#include "ao/core/image.h"
#include "ao/core/membership.h"
#include "ao/jobs/device.h"
#include "ao/scene/mesh.h"

namespace ao::view {

/// One scripted input, applied at the start of frame `frame` through the same handlers as the
/// mouse and keyboard: `orbit` and `pan` (args "dx,dy" in pixels), `zoom` (args: scroll steps),
/// `key` (args: one key name, as in the key list of docs/view.md), `set` (args: key=value, as --set).
struct ScriptedEvent {
  int frame = 0;
  std::string kind;
  std::string args;
};
/// Parses "FRAME:KIND:ARGS" (e.g. "3:orbit:40,0", "5:key:F", "2:set:view=error"); InputError otherwise.
ScriptedEvent parse_event(const std::string& text);

/// Everything the viewer starts from, already checked by the command line.
struct ViewSetup {
  std::shared_ptr<const Scene> scene;
  Camera camera;                    ///< The start view, as ao render would choose it; its size is the window's.
  std::string method = "containment";
  nlohmann::json params;            ///< The method's parameters (defaults plus -p).
  Falloff falloff;                  ///< R and membership the user asked for.
  float radius_basis = 1.0f;        ///< The length R fractions refer to (the diagonal ao render uses), > 0.
  std::uint32_t seed = 1;
  /// Where the method runs at the start (the panel and --set device switch it): the GPU backend
  /// borrows the window's context, which must then be OpenGL 4.3 (SystemError otherwise).
  Device device = Device::Cpu;
  int threads = 0;                  ///< 0: all cores.
  Image<float> ao_map;              ///< --ao-map: shown by the "map" view; empty if none.
  std::vector<std::string> sets;    ///< --set key=value, applied before the first frame.
  std::vector<ScriptedEvent> events;
  int frames = 0;                   ///< > 0: render this many frames and exit (headless scripts).
  int wait_reference_spp = 0;       ///< With frames: keep going until the reference has this many rays per pixel.
  bool benchmark = false;           ///< Recompute G-buffer and method every frame, as a moving camera would.
  bool json = false;                ///< Print per-stage ms, fps and the reference's state as JSON on exit.
  std::string screenshot;           ///< PNG written after the last frame; empty: none.
  std::string camera_out;           ///< Camera JSON written with the screenshot; empty: none.
};

/// Opens the window and runs until it is closed (or `frames` are done). Returns the exit code.
/// No display, or no OpenGL 3.3 (4.3 for the GPU device): SystemError with one line naming the problem.
int run_view(ViewSetup setup);

}  // namespace ao::view
