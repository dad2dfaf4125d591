// SPDX-License-Identifier: Apache-2.0
// What the Python module's bindings share: JSON <-> Python objects, images <-> numpy arrays
// without a copy where the layout allows, the request fields every job takes (scene, camera,
// falloff), and the Scene and GBuffer handles Python holds.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <nlohmann/json.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/image.h"
#include "ao/jobs/inputs.h"
#include "ao/scene/mesh.h"

namespace ao::python {

namespace py = pybind11;

/// Levels of lists and dicts to_json follows.
inline constexpr int kMaxNesting = 32;

/// A Python object (None, bool, int, float, str, os.PathLike, list, tuple, dict, numpy scalars and
/// arrays) as JSON. Another type is a TypeError naming `what` (a dict's entries are named
/// what.key, or key alone at the top, where `what` is empty, and in "params"); an integer beyond
/// 64 bits or nesting deeper than kMaxNesting (a list that contains itself) an InputError.
nlohmann::json to_json(py::handle object, const std::string& what);
/// `request[key]` when it is set (present and not None) as an int, a finite float, a str or a
/// bool; a TypeError naming `name` for another type, an InputError for an integer beyond int or a
/// float that is not finite.
std::optional<int> int_of(const nlohmann::json& request, const char* key, const std::string& name);
std::optional<float> float_of(const nlohmann::json& request, const char* key, const std::string& name);
std::optional<std::string> string_of(const nlohmann::json& request, const char* key, const std::string& name);
std::optional<bool> bool_of(const nlohmann::json& request, const char* key, const std::string& name);

/// JSON as plain Python objects.
py::object from_json(const nlohmann::json& j);

/// A 1-D float32 array that owns `values` (moved, not copied).
py::array to_array(std::vector<float>&& values);
/// An N x 3 array of numbers as N vectors (TypeError for what is not numbers, InputError naming
/// `what` for another shape).
std::vector<Vec3> rows_of_vec3(py::handle array, const std::string& what);

/// The images as numpy arrays that own them: the pixels are moved into the array's base object,
/// not copied. float32 H x W; Vec3 images H x W x 3; Vec2 H x W x 2; uint32 and uint8 H x W.
py::array to_array(Image<float>&& image);
py::array to_array(Image<Vec3>&& image);
py::array to_array(Image<Vec2>&& image);
py::array to_array(Image<std::uint32_t>&& image);
py::array to_array(Image<std::uint8_t>&& image);
/// A view of `image` that keeps `owner` (the Python object holding it) alive; read-only.
py::array view_array(const Image<Vec3>& image, py::handle owner);
py::array view_array(const Image<Vec2>& image, py::handle owner);
py::array view_array(const Image<std::uint32_t>& image, py::handle owner);

/// A scene Python holds: a file's, a built-in one, or one made from arrays; immutable.
struct SceneHandle {
  std::shared_ptr<const Scene> scene;
};

/// A G-buffer Python holds: rendered by ao.gbuffer or built from the caller's arrays.
struct GBufferHandle {
  std::shared_ptr<const GBuffer> gbuffer;
};

/// The scene argument of a job: None (the built-in default), a path or a built-in name, a list of
/// mesh files, or an ao.Scene.
SceneSource scene_source(py::handle scene);

/// The camera fields of `request` ("camera": {"eye", "target", "up", "fov", "width", "height"},
/// each optional) over `camera`'s defaults.
CameraRequest camera_request(const nlohmann::json& request, CameraRequest camera);
/// "radius", "radius_fraction", "membership", "tau" of `request`.
FalloffRequest falloff_request(const nlohmann::json& request);

/// A mesh from arrays: vertices N x 3, faces M x 3 (indices from 0), normals N x 3 and uvs N x 2
/// optional; checked and prepared (validate_and_prepare: InputError naming `name`).
std::shared_ptr<const Scene> scene_from_arrays(py::handle vertices, py::handle faces, py::handle normals, py::handle uvs, const std::string& name);

/// A G-buffer from the caller's arrays: unit camera-space normals H x W x 3, and camera-space
/// positions H x W x 3 or linear depths H x W (positions then rebuilt through each pixel centre);
/// albedo H x W x 3 optional (0.8 grey); object ids H x W optional (1 where covered). Covered
/// where the depth is finite, > 0 and below 1e9 (as a G-buffer file without coverage). `camera`:
/// its fov (and placement, when the caller knows it) and size, checked against the arrays.
std::shared_ptr<const GBuffer> gbuffer_from_arrays(py::handle normal, py::handle depth, py::handle position, py::handle albedo,
                                                   py::handle object_id, const Camera& camera);

/// The Camera a JSON object describes (eye, target, up, fov, width, height: camera_json.h).
Camera camera_from_dict(const nlohmann::json& j, const std::string& source);

}  // namespace ao::python
