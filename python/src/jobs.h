// SPDX-License-Identifier: Apache-2.0
// The job calls of the Python module (jobs.cpp). Each takes the request as a dict of the job
// layer's fields, built by ao/__init__.py from the keyword arguments.
#pragma once

#include <pybind11/pybind11.h>

#include "convert.h"

namespace ao::python {

// `progress`: None or a callable(stage, done, total) (Call).

/// run_render: {"visibility", "std_error" (raytraced), "color", "extras", "summary", "gbuffer"}.
py::dict render(py::handle scene, py::handle gbuffer, py::handle request, py::object progress);
/// render_provenance of the request, inputs not hashed: what ao.batch compares with a record on disk.
py::dict render_record(py::handle scene, py::handle gbuffer, py::handle request);
/// The G-buffer of a scene and camera, rendered as run_render renders it.
GBufferHandle gbuffer(py::handle scene, py::handle request, py::object progress);
/// run_bake of one mesh: {"map", "mask", "per_vertex", "summary"}. High to low: `high` is None, an
/// ao.Scene or a list of mesh files; `cage` None, an ao.Scene or a mesh file.
py::dict bake(py::handle mesh, py::handle request, py::object progress, py::handle high, py::handle cage);
/// bake_provenance of the request for its one mesh file, inputs not hashed.
py::dict bake_record(py::handle mesh, py::handle request, py::handle high, py::handle cage);
/// run_points: {"visibility", "std_error" (1-D float32, one per point), "summary"}.
py::dict occlusion(py::handle scene, py::handle points, py::handle normals, py::handle request, py::object progress);
/// run_compare: {"table" (table.json), "markdown", "images"}.
py::dict compare(py::handle scene, py::handle request, py::object progress);

}  // namespace ao::python
