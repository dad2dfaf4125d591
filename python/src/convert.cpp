// SPDX-License-Identifier: Apache-2.0
#include "convert.h"

#include <cmath>
#include <cstdint>
#include <limits>

#include "ao/core/error.h"
#include "ao/io/camera_json.h"

namespace ao::python {

namespace {

static_assert(sizeof(Vec3) == 3 * sizeof(float) && sizeof(Vec2) == 2 * sizeof(float), "images of Vec3 and Vec2 are float arrays");

std::string type_name(py::handle object) { return py::str(py::type::handle_of(object).attr("__name__")).cast<std::string>(); }

template <class T>
constexpr std::size_t channels() {
  if constexpr (std::is_same_v<T, Vec3>) return 3;
  else if constexpr (std::is_same_v<T, Vec2>) return 2;
  else return 1;
}
template <class T>
using Scalar = std::conditional_t<channels<T>() == 1, T, float>;

template <class T>
py::array array_over(const Image<T>& image, py::handle base) {
  const auto h = static_cast<py::ssize_t>(image.height()), w = static_cast<py::ssize_t>(image.width());
  constexpr auto c = static_cast<py::ssize_t>(channels<T>());
  constexpr auto pixel = static_cast<py::ssize_t>(sizeof(T));
  std::vector<py::ssize_t> shape = {h, w}, strides = {w * pixel, pixel};
  if (c > 1) {
    shape.push_back(c);
    strides.push_back(static_cast<py::ssize_t>(sizeof(float)));
  }
  return py::array(py::dtype::of<Scalar<T>>(), shape, strides, image.data(), base);
}

template <class T>
py::array owned_array(Image<T>&& image) {
  auto* held = new Image<T>(std::move(image));
  py::capsule base(held, [](void* p) { delete static_cast<Image<T>*>(p); });
  return array_over(*held, base);
}

template <class T>
py::array read_only(const Image<T>& image, py::handle owner) {
  py::array a = array_over(image, owner);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

Vec3 vec3_of(const nlohmann::json& j, const std::string& what) {
  if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number())
    throw InputError(what + ": expected three numbers x, y, z");
  const Vec3 v{j[0].get<float>(), j[1].get<float>(), j[2].get<float>()};
  if (!is_finite(v)) throw InputError(what + ": expected three finite numbers x, y, z");
  return v;
}

// `array` as a C-contiguous numpy array of T with `rank` dimensions, the last one `last` long
// (when > 0); InputError naming `what` and the shape otherwise.
template <class T>
py::array_t<T, py::array::c_style | py::array::forcecast> shaped(py::handle array, int rank, py::ssize_t last, const std::string& what) {
  if (array.is_none()) throw py::type_error(what + ": expected an array, got None");
  auto a = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!a) throw py::type_error(what + ": expected an array of numbers, got " + type_name(array));
  if (a.ndim() != rank || (last > 0 && a.shape(rank - 1) != last)) {
    std::string got;
    for (py::ssize_t k = 0; k < a.ndim(); ++k) got += (k ? " x " : "") + std::to_string(a.shape(k));
    throw InputError(what + ": expected an array of shape " + std::string(rank == 2 ? "N" : "H x W") + (last > 0 ? " x " + std::to_string(last) : "") +
                     ", got " + (a.ndim() == 0 ? std::string("a single value") : got));
  }
  return a;
}

// The numpy kind of `array`'s elements ('i', 'u', 'f', 'b', ...); 0 when it is not an array.
char kind_of(py::handle array) {
  const py::array a = py::array::ensure(array);
  return a ? a.dtype().kind() : 0;
}

// Numbers only: integers and floats, not None, booleans, complex numbers, strings or objects.
void require_numbers(py::handle array, const std::string& what) {
  if (array.is_none()) throw py::type_error(what + ": expected an array, got None");
  const char k = kind_of(array);
  if (k == 'i' || k == 'u' || k == 'f') return;
  const std::string got = k == 'b' ? "booleans" : k == 'c' ? "complex numbers" : k == 'U' || k == 'S' ? "strings" : "values of type " + type_name(array);
  throw py::type_error(what + ": expected an array of numbers, got " + got);
}

template <class V, int N>
std::vector<V> rows_of(py::handle array, std::size_t count, const std::string& what) {
  require_numbers(array, what);
  const auto a = shaped<float>(array, 2, N, what);
  if (count != static_cast<std::size_t>(-1) && static_cast<std::size_t>(a.shape(0)) != count)
    throw InputError(what + ": expected one row per vertex (" + std::to_string(count) + "), got " + std::to_string(a.shape(0)));
  std::vector<V> out(static_cast<std::size_t>(a.shape(0)));
  std::memcpy(static_cast<void*>(out.data()), a.data(), out.size() * sizeof(V));
  return out;
}

}  // namespace

namespace {

// The name of `key` inside the value named `what`: the request's own keys and the method
// parameters are the keyword arguments themselves ("slices", "camera.eye").
std::string member_name(const std::string& what, const std::string& key) {
  return what.empty() || what == "params" ? key : what + "." + key;
}

nlohmann::json json_of(py::handle o, const std::string& what, int depth) {
  // Deeper than any value ao reads (a camera's vector is two levels, a compare's parameters three);
  // a list or dict that contains itself ends here too, instead of recursing until the stack ends.
  if (depth > kMaxNesting)
    throw InputError(what + ": nested deeper than " + std::to_string(kMaxNesting) + " levels (a list or dict that contains itself?)");
  if (o.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(o)) return o.cast<bool>();
  if (PyLong_Check(o.ptr())) {
    const long long v = PyLong_AsLongLong(o.ptr());
    if (v == -1 && PyErr_Occurred()) {
      PyErr_Clear();
      throw InputError(what + ": the integer " + py::str(o).cast<std::string>() + " is out of range");
    }
    return static_cast<std::int64_t>(v);
  }
  if (PyFloat_Check(o.ptr())) return o.cast<double>();
  if (py::isinstance<py::str>(o)) return o.cast<std::string>();
  if (py::hasattr(o, "__fspath__")) {
    const py::object p = py::module_::import("os").attr("fspath")(o);
    if (!py::isinstance<py::str>(p)) throw py::type_error(what + ": expected a str file name, got " + type_name(p));
    return p.cast<std::string>();
  }
  const py::module_ np = py::module_::import("numpy");
  if (py::isinstance(o, np.attr("generic"))) return json_of(o.attr("item")(), what, depth + 1);
  if (py::isinstance(o, np.attr("ndarray"))) return json_of(o.attr("tolist")(), what, depth + 1);
  if (py::isinstance<py::dict>(o)) {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& [k, v] : o.cast<py::dict>()) {
      if (!py::isinstance<py::str>(k)) throw py::type_error(what + ": keys must be strings, got " + type_name(k));
      const std::string key = k.cast<std::string>();
      j[key] = json_of(v, member_name(what, key), depth + 1);
    }
    return j;
  }
  if (py::isinstance<py::list>(o) || py::isinstance<py::tuple>(o)) {
    nlohmann::json j = nlohmann::json::array();
    for (py::handle item : o) j.push_back(json_of(item, what, depth + 1));
    return j;
  }
  throw py::type_error(what + ": a value of type " + type_name(o) + " is not a number, string, bool, list or dict");
}

}  // namespace

nlohmann::json to_json(py::handle o, const std::string& what) { return json_of(o, what, 0); }

namespace {

const nlohmann::json* set_value(const nlohmann::json& request, const char* key) {
  const auto it = request.find(key);
  return it == request.end() || it->is_null() ? nullptr : &*it;
}

std::string json_type(const nlohmann::json& j) {
  if (j.is_string()) return "str";
  if (j.is_boolean()) return "bool";
  if (j.is_number_integer()) return "int";
  if (j.is_number()) return "float";
  return j.is_array() ? "list" : "dict";
}

}  // namespace

std::optional<int> int_of(const nlohmann::json& request, const char* key, const std::string& name) {
  const nlohmann::json* v = set_value(request, key);
  if (!v) return std::nullopt;
  if (!v->is_number_integer()) throw py::type_error(name + ": expected an integer, got " + json_type(*v));
  const std::int64_t i = v->get<std::int64_t>();
  if (i < std::numeric_limits<int>::min() || i > std::numeric_limits<int>::max())
    throw InputError(name + ": " + std::to_string(i) + " is out of range");
  return static_cast<int>(i);
}

std::optional<float> float_of(const nlohmann::json& request, const char* key, const std::string& name) {
  const nlohmann::json* v = set_value(request, key);
  if (!v) return std::nullopt;
  if (!v->is_number() || v->is_boolean()) throw py::type_error(name + ": expected a number, got " + json_type(*v));
  const double d = v->get<double>();
  if (!std::isfinite(d) || std::abs(d) > std::numeric_limits<float>::max()) {
    // As Python spells the value: JSON has no NaN or infinity, and nlohmann dumps them as null.
    const std::string got = std::isnan(d) ? "nan" : std::isinf(d) ? (d > 0 ? "inf" : "-inf") : v->dump();
    throw InputError(name + ": expected a finite number, got " + got);
  }
  return static_cast<float>(d);
}

std::optional<std::string> string_of(const nlohmann::json& request, const char* key, const std::string& name) {
  const nlohmann::json* v = set_value(request, key);
  if (!v) return std::nullopt;
  if (!v->is_string()) throw py::type_error(name + ": expected a string, got " + json_type(*v));
  return v->get<std::string>();
}

std::optional<bool> bool_of(const nlohmann::json& request, const char* key, const std::string& name) {
  const nlohmann::json* v = set_value(request, key);
  if (!v) return std::nullopt;
  if (!v->is_boolean()) throw py::type_error(name + ": expected True or False, got " + json_type(*v));
  return v->get<bool>();
}

py::object from_json(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::null: return py::none();
    case nlohmann::json::value_t::boolean: return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer: return py::int_(j.get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned: return py::int_(j.get<std::uint64_t>());
    case nlohmann::json::value_t::number_float: return py::float_(j.get<double>());
    case nlohmann::json::value_t::string: return py::str(j.get<std::string>());
    case nlohmann::json::value_t::array: {
      py::list l;
      for (const auto& v : j) l.append(from_json(v));
      return l;
    }
    case nlohmann::json::value_t::object: {
      py::dict d;
      for (const auto& [k, v] : j.items()) d[py::str(k)] = from_json(v);
      return d;
    }
    default: return py::none();
  }
}

py::array to_array(Image<float>&& image) { return owned_array(std::move(image)); }
py::array to_array(std::vector<float>&& values) {
  auto* held = new std::vector<float>(std::move(values));
  return py::array_t<float>({static_cast<py::ssize_t>(held->size())}, {static_cast<py::ssize_t>(sizeof(float))}, held->data(),
                            py::capsule(held, [](void* p) { delete static_cast<std::vector<float>*>(p); }));
}
std::vector<Vec3> rows_of_vec3(py::handle array, const std::string& what) { return rows_of<Vec3, 3>(array, static_cast<std::size_t>(-1), what); }
py::array to_array(Image<Vec3>&& image) { return owned_array(std::move(image)); }
py::array to_array(Image<Vec2>&& image) { return owned_array(std::move(image)); }
py::array to_array(Image<std::uint32_t>&& image) { return owned_array(std::move(image)); }
py::array to_array(Image<std::uint8_t>&& image) { return owned_array(std::move(image)); }
py::array view_array(const Image<Vec3>& image, py::handle owner) { return read_only(image, owner); }
py::array view_array(const Image<Vec2>& image, py::handle owner) { return read_only(image, owner); }
py::array view_array(const Image<std::uint32_t>& image, py::handle owner) { return read_only(image, owner); }

SceneSource scene_source(py::handle scene) {
  SceneSource source;
  if (scene.is_none()) return source;
  if (py::isinstance<SceneHandle>(scene)) {
    source.scene = scene.cast<const SceneHandle&>().scene;
    return source;
  }
  const nlohmann::json j = to_json(scene, "scene");
  if (j.is_string()) {
    source.args = {j.get<std::string>()};
  } else if (j.is_array() && !j.empty() && std::all_of(j.begin(), j.end(), [](const nlohmann::json& v) { return v.is_string(); })) {
    for (const auto& v : j) source.args.push_back(v.get<std::string>());
  } else {
    throw InputError("scene: expected a mesh file, a built-in scene name, a list of mesh files or an ao.Scene, got " + type_name(scene));
  }
  return source;
}

CameraRequest camera_request(const nlohmann::json& request, CameraRequest camera) {
  const nlohmann::json c = request.value("camera", nlohmann::json());
  if (c.is_null()) return camera;
  if (!c.is_object()) throw InputError("camera: expected an ao.Camera or a dict, got " + c.dump());
  auto set = [&](const char* key) { return c.contains(key) && !c[key].is_null(); };
  if (set("eye")) camera.eye = vec3_of(c["eye"], "camera.eye");
  if (set("target")) camera.target = vec3_of(c["target"], "camera.target");
  if (set("up")) camera.up = vec3_of(c["up"], "camera.up");
  if (const auto fov = float_of(c, "fov", "camera.fov")) camera.fov = *fov;
  if (const auto width = int_of(c, "width", "camera.width")) camera.width = *width;
  if (const auto height = int_of(c, "height", "camera.height")) camera.height = *height;
  camera.validate();
  return camera;
}

FalloffRequest falloff_request(const nlohmann::json& request) {
  FalloffRequest f;
  f.membership = membership_from_name(string_of(request, "membership", "membership").value_or("step"));
  f.radius = float_of(request, "radius", "radius");
  f.radius_fraction = float_of(request, "radius_fraction", "radius_fraction").value_or(f.radius_fraction);
  f.tau = float_of(request, "tau", "tau").value_or(f.tau);
  f.validate();
  return f;
}

std::shared_ptr<const Scene> scene_from_arrays(py::handle vertices, py::handle faces, py::handle normals, py::handle uvs, const std::string& name) {
  Mesh mesh;
  mesh.name = name;
  mesh.positions = rows_of<Vec3, 3>(vertices, static_cast<std::size_t>(-1), name + ": vertices");
  // Indices are whole numbers: integers, or floats that hold them (3.0); 0.5 is not vertex 0.
  require_numbers(faces, name + ": faces");
  const auto f = shaped<double>(faces, 2, 3, name + ": faces");
  mesh.indices.resize(static_cast<std::size_t>(f.size()));
  for (std::size_t i = 0; i < mesh.indices.size(); ++i) {
    const double v = f.data()[i];
    const std::string face = name + ": face " + std::to_string(i / 3);
    if (!(v == std::floor(v))) throw InputError(face + " has the index " + py::str(py::float_(v)).cast<std::string>() + ", not a whole number");
    if (v < 0 || v >= static_cast<double>(mesh.positions.size()))
      throw InputError(face + " uses vertex " + std::to_string(static_cast<long long>(v)) + ", the mesh has " + std::to_string(mesh.positions.size()));
    mesh.indices[i] = static_cast<std::uint32_t>(v);
  }
  if (!normals.is_none()) {
    mesh.normals = rows_of<Vec3, 3>(normals, mesh.positions.size(), name + ": normals");
    for (std::size_t v = 0; v < mesh.normals.size(); ++v)
      if (!is_finite(mesh.normals[v]) || !(length(mesh.normals[v]) > 0))
        throw InputError(name + ": normals: row " + std::to_string(v) + " is not a finite non-zero vector (give unit normals, or none)");
  }
  if (!uvs.is_none()) mesh.uvs = rows_of<Vec2, 2>(uvs, mesh.positions.size(), name + ": uvs");
  auto scene = std::make_shared<Scene>();
  scene->name = name;
  scene->meshes.push_back(std::move(mesh));
  validate_and_prepare(*scene);
  return scene;
}

std::shared_ptr<const GBuffer> gbuffer_from_arrays(py::handle normal, py::handle depth, py::handle position, py::handle albedo,
                                                   py::handle object_id, const Camera& camera) {
  require_numbers(normal, "normal");
  if (!depth.is_none()) require_numbers(depth, "depth");
  if (!position.is_none()) require_numbers(position, "position");
  if (!albedo.is_none()) require_numbers(albedo, "albedo");
  if (!object_id.is_none() && kind_of(object_id) != 'i' && kind_of(object_id) != 'u')
    throw py::type_error("object_id: expected an array of integers (0 = background)");
  const auto n = shaped<float>(normal, 3, 3, "normal");
  const int h = static_cast<int>(n.shape(0)), w = static_cast<int>(n.shape(1));
  if (camera.width != w || camera.height != h)
    throw InputError("normal: the arrays are " + std::to_string(w) + "x" + std::to_string(h) + " pixels, the camera " +
                     std::to_string(camera.width) + "x" + std::to_string(camera.height));
  if (depth.is_none() == position.is_none()) throw InputError("gbuffer: give either depth (H x W) or position (H x W x 3)");
  auto expect_size = [&](const py::array& a, const char* what) {
    if (a.shape(0) != h || a.shape(1) != w) throw InputError(std::string(what) + ": expected " + std::to_string(h) + " x " + std::to_string(w) + " pixels like normal");
  };
  std::optional<py::array_t<float, py::array::c_style | py::array::forcecast>> z, p, a;
  std::optional<py::array_t<std::uint32_t, py::array::c_style | py::array::forcecast>> id;
  if (!depth.is_none()) expect_size(*(z = shaped<float>(depth, 2, 0, "depth")), "depth");
  if (!position.is_none()) expect_size(*(p = shaped<float>(position, 3, 3, "position")), "position");
  if (!albedo.is_none()) expect_size(*(a = shaped<float>(albedo, 3, 3, "albedo")), "albedo");
  if (!object_id.is_none()) {
    const auto wide = shaped<std::int64_t>(object_id, 2, 0, "object_id");
    for (py::ssize_t i = 0; i < wide.size(); ++i)
      if (wide.data()[i] < 0 || wide.data()[i] > std::numeric_limits<std::uint32_t>::max())
        throw InputError("object_id: " + std::to_string(wide.data()[i]) + " is not an id in [0, 4294967295]");
    expect_size(*(id = shaped<std::uint32_t>(object_id, 2, 0, "object_id")), "object_id");
  }

  auto g = std::make_shared<GBuffer>();
  g->camera = camera;
  g->position = Image<Vec3>(w, h, Vec3{});
  g->normal = Image<Vec3>(w, h, Vec3{});
  g->albedo = Image<Vec3>(w, h, Vec3{});
  g->object_id = Image<std::uint32_t>(w, h, 0u);
  const auto* nv = reinterpret_cast<const Vec3*>(n.data());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      const Vec3 pos = p ? reinterpret_cast<const Vec3*>(p->data())[i] : camera.camera_direction(x + 0.5f, y + 0.5f) * z->data()[i];
      const float d = z ? z->data()[i] : -pos.z;
      // Covered as in a G-buffer file without coverage (docs/gbuffer.md): depth finite, > 0 and
      // below 1e9, where renderers put their background; or where the caller's id says so.
      const bool covered = id ? id->data()[i] != 0 : (std::isfinite(d) && d > 0 && d < 1e9f);
      if (!covered) continue;
      const std::string at = "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ")";
      if (!(std::isfinite(d) && d > 0) || !is_finite(pos) || !(pos.z < 0)) throw InputError("gbuffer: " + at + " is covered but its depth or position is not in front of the camera");
      const float len = length(nv[i]);
      if (!is_finite(nv[i]) || !(len > 0)) throw InputError("gbuffer: " + at + ": the normal is not a finite non-zero vector");
      // Unit normals are kept bit for bit (a renormalised unit vector may differ in the last bit);
      // others are normalised, as a G-buffer file's are on reading.
      g->normal[i] = std::abs(len - 1.0f) < 1e-5f ? nv[i] : nv[i] / len;
      g->position[i] = pos;
      g->albedo[i] = a ? reinterpret_cast<const Vec3*>(a->data())[i] : Vec3{0.8f, 0.8f, 0.8f};
      if (!is_finite(g->albedo[i])) throw InputError("gbuffer: " + at + ": the albedo is not finite");
      g->object_id[i] = id ? id->data()[i] : 1u;
    }
  return g;
}

Camera camera_from_dict(const nlohmann::json& j, const std::string& source) { return camera_from_json(j, Camera{}, source); }

}  // namespace ao::python
