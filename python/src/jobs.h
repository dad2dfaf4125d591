// The job calls of the Python module (jobs.cpp). Each takes the request as a dict of the job
// layer's fields, built by ao/__init__.py from the keyword arguments.
#pragma once

#include <pybind11/pybind11.h>

#include "convert.h"

namespace ao::python {

/// run_render: {"visibility", "std_error" (raytraced), "color", "extras", "summary", "gbuffer"}.
py::dict render(py::handle scene, py::handle gbuffer, py::handle request);
/// The G-buffer of a scene and camera, rendered as run_render renders it.
GBufferHandle gbuffer(py::handle scene, py::handle request);
/// run_bake of one mesh: {"map", "mask", "per_vertex", "summary"}.
py::dict bake(py::handle mesh, py::handle request);
/// run_compare: {"table" (table.json), "markdown", "images"}.
py::dict compare(py::handle scene, py::handle request);

}  // namespace ao::python
