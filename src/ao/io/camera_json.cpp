// SPDX-License-Identifier: Apache-2.0
#include "ao/io/camera_json.h"

#include "ao/core/closest_name.h"
#include "ao/core/error.h"
#include "ao/io/atomic_file.h"
#include "ao/io/io_error_internal.h"
#include "ao/io/json_text.h"

namespace ao {

namespace {

nlohmann::json vec_json(Vec3 v) { return nlohmann::json::array({v.x, v.y, v.z}); }

Vec3 read_vec(const nlohmann::json& j, const char* key, const std::string& source) {
  const nlohmann::json& v = j.at(key);
  if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number())
    throw InputError(source + ": camera '" + key + "' must be an array of three numbers, got " + json_excerpt(v));
  return {v[0].get<float>(), v[1].get<float>(), v[2].get<float>()};
}

}  // namespace

nlohmann::json camera_to_json(const Camera& c) {
  return {{"eye", vec_json(c.eye)}, {"target", vec_json(c.target)}, {"up", vec_json(c.up)},
          {"fov", c.vertical_fov_deg}, {"width", c.width}, {"height", c.height}};
}

Camera camera_from_json(const nlohmann::json& j, const Camera& defaults, const std::string& source) {
  if (!j.is_object()) throw InputError(source + ": a camera must be a JSON object with eye, target, up and fov");
  for (const char* key : {"eye", "target", "up", "fov"})
    if (!j.contains(key)) throw InputError(source + ": camera has no '" + key + "' (needs eye, target, up, fov; width, height optional)");
  for (const auto& [key, value] : j.items())
    if (key != "eye" && key != "target" && key != "up" && key != "fov" && key != "width" && key != "height")
      throw InputError(source + ": unknown camera field '" + io_detail::printable(key, 40) + "' (known: eye, target, up, fov, width, height)" +
                       did_you_mean(key, "eye, target, up, fov, width, height"));
  Camera c = defaults;
  c.eye = read_vec(j, "eye", source);
  c.target = read_vec(j, "target", source);
  c.up = read_vec(j, "up", source);
  if (!j["fov"].is_number()) throw InputError(source + ": camera 'fov' must be a number of degrees, got " + json_excerpt(j["fov"]));
  c.vertical_fov_deg = j["fov"].get<float>();
  for (const char* key : {"width", "height"}) {
    if (!j.contains(key)) continue;
    const nlohmann::json& v = j[key];
    if (!v.is_number_integer() || v.get<long long>() < 1 || v.get<long long>() > 65536)
      throw InputError(source + ": camera '" + key + "' must be a whole number of pixels in [1, 65536], got " + json_excerpt(v));
    (key[0] == 'w' ? c.width : c.height) = v.get<int>();
  }
  try {
    c.validate();
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
  return c;
}

Camera read_camera_file(const std::filesystem::path& path, const Camera& defaults) {
  return camera_from_json(read_json_file(path, "a camera: eye, target, up, fov"), defaults, path.string());
}

void write_camera_file(const std::filesystem::path& path, const Camera& camera) {
  write_bytes_atomically(path, camera_to_json(camera).dump(2) + "\n");
}

}  // namespace ao
