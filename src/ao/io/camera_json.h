// SPDX-License-Identifier: Apache-2.0
// A camera as a small JSON file, so a view found interactively (`ao view`) can be rendered again
// offline (`ao render --camera cam.json`) and the other way round:
//
//   {"eye": [x, y, z], "target": [x, y, z], "up": [x, y, z], "fov": 40, "width": 960, "height": 540}
//
// World units; fov is the full vertical field of view in degrees. width and height are optional
// on input (the caller's size is kept when they are absent).
#pragma once

#include <filesystem>

#include <nlohmann/json.hpp>

#include "ao/core/camera.h"

namespace ao {

/// The camera as the JSON object above (floats written so that they read back bit for bit).
nlohmann::json camera_to_json(const Camera& camera);
/// Reads the fields above into `camera` (eye, target, up and fov required; width and height
/// optional) and validates it. InputError naming `source` and the field otherwise.
Camera camera_from_json(const nlohmann::json& j, const Camera& defaults, const std::string& source);
/// camera_from_json of a file; InputError naming the file if it cannot be read or parsed.
Camera read_camera_file(const std::filesystem::path& path, const Camera& defaults);
/// Writes camera_to_json atomically (atomic_file.h).
void write_camera_file(const std::filesystem::path& path, const Camera& camera);

}  // namespace ao
