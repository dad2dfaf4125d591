// SPDX-License-Identifier: Apache-2.0
// ao._ao: the compiled half of the Python module `ao` (python/ao/__init__.py is the other): the
// library's errors as Python exceptions, scenes and G-buffers as objects, the jobs, the parameter
// tables, and the few file helpers ao.batch needs. Docs: README "Python", docs/cluster.md.
#include <memory>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <tbb/global_control.h>

#include "ao/bake/tangents.h"
#include "ao/core/closest_name.h"
#include "ao/core/error.h"
#include "ao/core/params.h"
#include "ao/io/atomic_file.h"
#include "ao/io/camera_json.h"
#include "ao/io/image_io.h"
#include "ao/jobs/fields.h"
#include "ao/jobs/provenance.h"
#include "ao/registry/registry.h"
#include "ao/simd/depth_plane.h"
#include "ao/version.h"
#include "call.h"
#include "convert.h"
#include "field_names.h"
#include "jobs.h"

namespace ao::python {

namespace {

const char* type_text(ParamType t) {
  switch (t) {
    case ParamType::Int: return "int";
    case ParamType::Float: return "float";
    case ParamType::Bool: return "bool";
    case ParamType::Enum: return "enum";
    case ParamType::OptionalInt: return "int or None";
    case ParamType::OptionalFloat: return "float or None";
  }
  return "";
}

// One row of a parameter table, as ao.methods() lists it.
py::dict spec_dict(const ParamSpec& s) {
  py::dict d;
  d["name"] = s.name;
  d["type"] = type_text(s.type);
  d["default"] = from_json(s.default_value);
  d["valid"] = s.valid_text();
  d["unit"] = s.unit;
  d["help"] = s.help;
  if (s.type == ParamType::Enum) {
    d["choices"] = s.enum_names;
    d["range"] = py::none();
  } else if (s.type == ParamType::Bool) {
    d["range"] = py::none();
  } else {
    d["range"] = py::make_tuple(s.range.min, s.range.max);
    d["range_open"] = py::make_tuple(s.range.min_open, s.range.max_open);
  }
  return d;
}

// A Python list of f(x) for each x of `range`.
template <class Range, class F>
py::list list_of(const Range& range, F f) {
  py::list l;
  for (const auto& x : range) l.append(f(x));
  return l;
}

py::list methods() {
  return list_of(all_methods(), [](const MethodInfo& m) {
    py::dict d;
    d["name"] = std::string(m.name);
    d["summary"] = std::string(m.summary);
    d["ground_truth"] = m.ground_truth;
    d["needs_scene"] = m.needs_scene;
    d["extras"] = list_of(m.extras, [](std::string_view e) { return std::string(e); });
    d["params"] = list_of(m.params().specs(), spec_dict);
    return d;
  });
}

py::list param_tables() {
  return list_of(all_param_tables(), [](const ParamTableInfo& t) {
    py::dict d;
    d["name"] = std::string(t.name);
    d["params"] = list_of(t.schema().specs(), spec_dict);
    return d;
  });
}

// TBB's worker count for the calls that follow; 0 restores all cores.
void set_threads(int threads) {
  static std::unique_ptr<tbb::global_control> limit;
  if (threads < 0 || threads > 1024) throw InputError("threads: expected an integer in [0, 1024], got " + std::to_string(threads));
  limit.reset();
  if (threads > 0) limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
}

Camera camera_for_arrays(const nlohmann::json& c, py::handle normal) {
  const auto n = py::array::ensure(normal);
  if (!n || n.ndim() != 3) throw InputError("normal: expected an array of shape H x W x 3");
  Camera cam;
  cam.height = static_cast<int>(n.shape(0));
  cam.width = static_cast<int>(n.shape(1));
  const std::optional<float> fov = c.is_object() ? float_of(c, "fov", "camera.fov") : std::nullopt;
  if (!fov) throw InputError("camera.fov: the vertical field of view (degrees) the buffers were rendered with is needed");
  cam.vertical_fov_deg = *fov;
  nlohmann::json placed = camera_to_json(cam);
  for (const char* key : {"eye", "target", "up", "width", "height"})
    if (c.contains(key) && !c[key].is_null()) placed[key] = c[key];
  return camera_from_dict(placed, "camera");
}

void bind_scene(py::module_& m) {
  py::class_<SceneHandle>(m, "Scene", "A scene: mesh files, a built-in scene, or a mesh made from arrays. Immutable; pass it to render, bake, compare.")
      .def_static(
          "load",
          [](py::handle source) {
            const SceneSource s = scene_source(source);
            Call call;
            return call.run([&] {
              std::shared_ptr<const Scene> scene = s.load();
              for (const std::string& w : scene->warnings) call.reporter().warn(w);
              return SceneHandle{scene};
            });
          },
          py::arg("source"),
          "load(source) -> Scene\n\nA mesh file (OBJ, PLY, OFF, STL, glTF/GLB), a list of them (one scene), or a built-in scene name "
          "(default, plane, wedge, sphere-on-plane, box-room, displaced). A bad file raises ao.InputError naming it.")
      .def_static(
          "from_arrays",
          [](py::handle vertices, py::handle faces, py::handle normals, py::handle uvs, const std::string& name) {
            return SceneHandle{scene_from_arrays(vertices, faces, normals, uvs, name)};
          },
          py::arg("vertices"), py::arg("faces"), py::arg("normals") = py::none(), py::arg("uvs") = py::none(), py::arg("name") = "arrays",
          "from_arrays(vertices, faces, normals=None, uvs=None, name='arrays') -> Scene\n\nOne mesh: vertices N x 3 (world units), faces M x 3 "
          "(vertex indices from 0, counter-clockwise seen from the front), optional unit normals N x 3 and UVs N x 2. Checked as a file is "
          "(non-finite coordinates, indices out of range: ao.InputError naming `name`); degenerate triangles are dropped with a warning.")
      .def_property_readonly("name", [](const SceneHandle& s) { return s.scene->name; })
      .def_property_readonly("triangles", [](const SceneHandle& s) { return s.scene->triangle_count(); })
      .def_property_readonly("vertices", [](const SceneHandle& s) { return s.scene->vertex_count(); })
      .def_property_readonly("meshes", [](const SceneHandle& s) { return s.scene->meshes.size(); })
      .def_property_readonly("warnings", [](const SceneHandle& s) { return s.scene->warnings; })
      .def_property_readonly("bounds",
                             [](const SceneHandle& s) {
                               const Bounds3 b = s.scene->bounds();
                               return py::make_tuple(py::make_tuple(b.lo.x, b.lo.y, b.lo.z), py::make_tuple(b.hi.x, b.hi.y, b.hi.z));
                             })
      .def(
          "tangents",
          [](const SceneHandle& s) {
            // Every triangle corner of every mesh, in order: tangent x, y, z and the bitangent's sign.
            std::vector<float> values;
            for (const Mesh& mesh : s.scene->meshes) {
              if (mesh.uvs.empty()) throw InputError(s.scene->name + ": mesh '" + mesh.name + "' has no UVs, so it has no tangent frames");
              for (const CornerTangent& c : mikktspace_tangents(mesh)) values.insert(values.end(), {c.t.x, c.t.y, c.t.z, c.sign});
            }
            py::array_t<float> out({static_cast<py::ssize_t>(values.size() / 4), py::ssize_t{4}});
            std::copy(values.begin(), values.end(), out.mutable_data());
            return out;
          },
          "MikkTSpace tangent frames (as Blender's mesh.calc_tangents, glTF and engines build them) of every triangle corner, meshes in "
          "order: corners x 4 float32, the unit tangent and the bitangent's sign (bitangent = sign * cross(normal, tangent)).")
      .def("__repr__", [](const SceneHandle& s) {
        return "<ao.Scene '" + s.scene->name + "': " + std::to_string(s.scene->triangle_count()) + " triangles>";
      });
}

void bind_gbuffer(py::module_& m) {
  py::class_<GBufferHandle>(m, "GBuffer",
                            "A G-buffer (docs/gbuffer.md): camera-space positions, unit normals (facing the camera), albedo, object ids "
                            "(0 = background). Arrays are read-only views, H x W (x 3).")
      .def_static(
          "from_arrays",
          [](py::handle normal, py::handle depth, py::handle position, py::handle albedo, py::handle object_id, py::handle camera) {
            const Camera cam = camera_for_arrays(to_json(camera, "camera"), normal);
            return GBufferHandle{gbuffer_from_arrays(normal, depth, position, albedo, object_id, cam)};
          },
          py::arg("normal"), py::kw_only(), py::arg("depth") = py::none(), py::arg("position") = py::none(), py::arg("albedo") = py::none(),
          py::arg("object_id") = py::none(), py::arg("camera"), "from_arrays(normal, *, depth=None, position=None, albedo=None, object_id=None, camera) -> GBuffer\n\nSee ao.gbuffer_from_arrays.")
      .def_property_readonly("position", [](py::object self) { return view_array(self.cast<const GBufferHandle&>().gbuffer->position, self); })
      .def_property_readonly("normal", [](py::object self) { return view_array(self.cast<const GBufferHandle&>().gbuffer->normal, self); })
      .def_property_readonly("albedo",
                             [](py::object self) -> py::object {
                               const GBuffer& g = *self.cast<const GBufferHandle&>().gbuffer;
                               return g.albedo.empty() ? py::object(py::none()) : py::object(view_array(g.albedo, self));
                             })
      .def_property_readonly("uv",
                             [](py::object self) -> py::object {
                               const GBuffer& g = *self.cast<const GBufferHandle&>().gbuffer;
                               return g.uv.empty() ? py::object(py::none()) : py::object(view_array(g.uv, self));
                             })
      .def_property_readonly("object_id", [](py::object self) { return view_array(self.cast<const GBufferHandle&>().gbuffer->object_id, self); })
      .def_property_readonly("depth", [](const GBufferHandle& g) { return to_array(depth_plane(*g.gbuffer)); })
      .def_property_readonly("camera", [](const GBufferHandle& g) { return from_json(camera_to_json(g.gbuffer->camera)); })
      .def_property_readonly("width", [](const GBufferHandle& g) { return g.gbuffer->width(); })
      .def_property_readonly("height", [](const GBufferHandle& g) { return g.gbuffer->height(); })
      .def("__repr__", [](const GBufferHandle& g) { return "<ao.GBuffer " + std::to_string(g.gbuffer->width()) + "x" + std::to_string(g.gbuffer->height()) + ">"; });
}

void bind_files(py::module_& m) {
  m.def("read_camera", [](const std::filesystem::path& path) { return from_json(camera_to_json(read_camera_file(path, Camera{}))); }, py::arg("path"));
  m.def("check_camera", [](py::handle camera) { return from_json(camera_to_json(camera_from_dict(to_json(camera, "camera"), "camera"))); },
        py::arg("camera"));
  m.def(
      "write_camera", [](const std::filesystem::path& path, py::handle camera) { write_camera_file(path, camera_from_dict(to_json(camera, "camera"), path.string())); },
      py::arg("path"), py::arg("camera"));
  m.def(
      "write_text",
      [](const std::filesystem::path& path, const std::string& text) { write_bytes_atomically(path, text); },
      py::arg("path"), py::arg("text"), "Writes `text` to `path` atomically (a temporary file beside it, renamed into place).");
  m.def(
      "read_image", [](const std::filesystem::path& path, bool rgb) { return rgb ? to_array(read_rgb_image(path)) : to_array(read_image(path)); },
      py::arg("path"), py::arg("rgb") = false,
      "read_image(path, rgb=False) -> numpy.ndarray\n\nOne channel of an image file as float32 H x W (rgb=True: red, green and blue, "
      "H x W x 3, as bent normals are written), as ao reads its own outputs: EXR floats as "
      "stored, PNG values normalised to [0, 1] (no sRGB decoding). A bad file raises ao.InputError naming it.");
  m.def("remove_abandoned_temporaries", [](const std::filesystem::path& path) { return remove_abandoned_temporaries(path); }, py::arg("path"),
        "Removes the temporary files other processes left for the output `path` (io/atomic_file.h); returns how many.");
}

}  // namespace

}  // namespace ao::python

PYBIND11_MODULE(_ao, m) {
  namespace py = pybind11;
  using namespace ao::python;
  m.doc() = "ao's library bindings; use the package ao (python/ao/__init__.py).";
  m.attr("__version__") = AO_VERSION_STRING;
  static py::exception<ao::InputError> input_error(m, "InputError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ao::InputError& e) {
      // The job layer names request fields ("BakeRequest::padding"); Python names its keywords.
      PyErr_SetString(input_error.ptr(), e.message(keyword_name).c_str());
    } catch (const ao::SystemError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const nlohmann::json::exception&) {
      // The conversions check every type they read (convert.h); should one slip through, the JSON
      // library's text stays out of the message.
      PyErr_SetString(PyExc_TypeError, "ao: an argument has the wrong type for the library (expected numbers, strings, lists or dicts as documented)");
    }
  });
  bind_scene(m);
  bind_gbuffer(m);
  bind_files(m);
  m.def("render", &render, py::arg("scene"), py::arg("gbuffer"), py::arg("request"), py::arg("progress") = py::none());
  m.def("render_record", &render_record, py::arg("scene"), py::arg("gbuffer"), py::arg("request"),
        "The provenance record the request's outputs would get (inputs by role and path, not hashed): what ao.batch compares.");
  m.def("bake_record", &bake_record, py::arg("mesh"), py::arg("request"), py::arg("high") = py::none(), py::arg("cage") = py::none(),
        "The provenance record the request's outputs would get for its one mesh file (inputs not hashed).");
  m.def("gbuffer", &gbuffer, py::arg("scene"), py::arg("request"), py::arg("progress") = py::none());
  m.def("bake", &bake, py::arg("mesh"), py::arg("request"), py::arg("progress") = py::none(), py::arg("high") = py::none(), py::arg("cage") = py::none());
  m.def("occlusion", &occlusion, py::arg("scene"), py::arg("points"), py::arg("normals"), py::arg("request"), py::arg("progress") = py::none());
  m.def("compare", &compare, py::arg("scene"), py::arg("request"), py::arg("progress") = py::none());
  m.def("build_info", [] { return from_json(ao::build_info()); }, "{'version', 'simd_target'}: what every JSON output of ao names as 'ao'.");
  m.def("keyword_table", &keyword_table, "[(request field, keyword)]: the names ao's errors give the job layer's request fields.");
  m.def("request_fields", [] {
    std::vector<std::string> out;
    for (std::string_view f : ao::fields::kAll) out.emplace_back(f);
    return out;
  });
  m.def("methods", &methods);
  m.def("param_tables", &param_tables);
  m.def("set_threads", &set_threads, py::arg("threads"));
  m.def("did_you_mean", [](const std::string& typed, const std::vector<std::string>& names) { return ao::did_you_mean(typed, names); },
        py::arg("typed"), py::arg("names"), "\"; did you mean 'x'?\" naming the name closest to typed, or \"\": the suffix of ao's errors about a name.");
}
