# SPDX-License-Identifier: Apache-2.0
"""Python errors in Python words: every wrong shape, dtype, type, None, NaN, string or huge value is
a TypeError or ValueError naming the argument, never the binding's or the JSON library's text, and
never a crash (a list that contains itself, nesting 100,000 deep). The job layer's errors name its
request fields; the module names them by its keyword arguments, from a table that covers every
field (python/src/field_names.cpp)."""

import doctest
import math
import re

import numpy as np
import pytest

import ao
from conftest import bumpy_grid

CAM = ao.Camera(width=16, height=9)
V, F, T = bumpy_grid(n=4)


def cyclic():
    x = []
    x.append(x)
    return x


def deep(levels):
    d = [0.0]
    for _ in range(levels):
        d = [d]
    return d


# (what is called, the exception, what its message starts with)
CASES = [
    # shapes
    (lambda: ao.Scene.from_arrays(np.zeros((3, 2)), F), ValueError, "arrays: vertices: expected an array of shape N x 3, got 3 x 2"),
    (lambda: ao.Scene.from_arrays(V, [[0, 1, 2, 3]]), ValueError, "arrays: faces: expected an array of shape N x 3, got 1 x 4"),
    (lambda: ao.Scene.from_arrays(V, F, uvs=np.zeros((2, 2))), ValueError, "arrays: uvs: expected one row per vertex"),
    (lambda: ao.gbuffer_from_arrays(np.zeros((4, 4)), depth=np.ones((4, 4)), camera={"fov": 40}), ValueError, "normal: expected an array"),
    (lambda: ao.occlusion("plane", np.zeros((2, 2)), np.zeros((2, 3))), ValueError, "points: expected an array of shape N x 3"),
    (lambda: ao.occlusion("plane", np.zeros((2, 3)), [[0, 1, 0]]), ValueError, "normals: 1 normals for 2 points"),
    # dtypes
    (lambda: ao.Scene.from_arrays([["a", "b", "c"]], F), TypeError, "arrays: vertices: expected an array of numbers, got strings"),
    (lambda: ao.Scene.from_arrays(V, np.ones((1, 3), dtype=bool)), TypeError, "arrays: faces: expected an array of numbers, got booleans"),
    (lambda: ao.Scene.from_arrays(V, [[0, 1, 2.5]]), ValueError, "arrays: face 0 has the index 2.5, not a whole number"),
    (lambda: ao.Scene.from_arrays(V, np.array([[0, 1, 2]]) + 1j), TypeError, "arrays: faces: expected an array of numbers, got complex"),
    (lambda: ao.gbuffer_from_arrays(np.ones((4, 4, 3)), depth=np.ones((4, 4)), object_id=np.ones((4, 4)), camera={"fov": 40}),
     TypeError, "object_id: expected an array of integers"),
    # None and wrong types
    (lambda: ao.Scene.from_arrays(None, F), TypeError, "arrays: vertices: expected an array, got None"),
    (lambda: ao.render("wedge", 3), TypeError, "camera: expected an ao.Camera, a dict or a camera JSON file, got int"),
    (lambda: ao.render(3.5, CAM), TypeError, "scene: expected a mesh file"),
    (lambda: ao.render("wedge", CAM, None), TypeError, "method: expected a string, got NoneType"),
    (lambda: ao.render("wedge", CAM, gbuffer=np.zeros((4, 4))), TypeError, "gbuffer: expected an ao.GBuffer"),
    (lambda: ao.bake(None), TypeError, "mesh: expected a file name"),
    (lambda: ao.compare("wedge", methods=3), TypeError, "methods: expected a list of method names, got int"),
    (lambda: ao.render("wedge", CAM, progress=3), TypeError, "progress: expected None, True or a callable"),
    # strings where numbers go
    (lambda: ao.render("wedge", CAM, spp="4"), TypeError, "spp: expected an integer, got str '4'"),
    (lambda: ao.render("wedge", CAM, seed="1"), TypeError, "seed: expected an integer, got str '1'"),
    (lambda: ao.render("wedge", CAM, radius="0.5"), TypeError, "radius: expected a number, got str '0.5'"),
    (lambda: ao.bake("grid.obj", padding="2"), TypeError, "padding: expected an integer, got str '2'"),
    (lambda: ao.Camera(width="64"), TypeError, "camera.width: expected an integer, got str '64'"),
    (lambda: ao.Camera(eye="1,2,3"), TypeError, "camera.eye: expected three numbers x, y, z, got str"),
    (lambda: ao.set_threads("2"), TypeError, "threads: expected an integer, got str '2'"),
    (lambda: ao.render("wedge", CAM, "gtao", slices="4"), ValueError, 'gtao: slices must be an integer in [1, 16], got "4"'),
    (lambda: ao.render("wedge", CAM, extras=1), TypeError, "extras: expected True or False, got int 1"),
    # NaN and infinities
    (lambda: ao.render("wedge", CAM, radius=math.nan), ValueError, "radius: expected a finite number, got nan"),
    (lambda: ao.Camera(fov=math.inf), ValueError, "camera.fov: expected a finite number, got inf"),
    (lambda: ao.bake("grid.obj", denoise=math.nan), ValueError, "denoise: expected a finite number, got nan"),
    (lambda: ao.Camera(eye=(0, math.nan, 0)), ValueError, "camera.eye[1]: expected a finite number, got nan"),
    (lambda: ao.Scene.from_arrays(np.full((3, 3), np.nan), [[0, 1, 2]]), ValueError, "arrays"),
    (lambda: ao.Scene.from_arrays(V, F, normals=np.zeros_like(V)), ValueError, "arrays: normals: row 0 is not a finite non-zero vector"),
    (lambda: ao.occlusion("plane", [[0, math.nan, 0]], [[0, 1, 0]]), ValueError, "points: point 0 is not finite"),
    (lambda: ao.occlusion("plane", [[0, 0, 0]], [[0, 0, 0]]), ValueError, "normals: normal 0 is not a finite non-zero vector"),
    # out of range, huge
    (lambda: ao.Camera(width=10 ** 12), ValueError, "camera.width: 1000000000000 is out of range"),
    (lambda: ao.render("wedge", ao.Camera(width=10 ** 6, height=9)), ValueError, "camera.width must be in [1, 32768] pixels, got 1000000"),
    (lambda: ao.render("wedge", CAM, spp=10 ** 20), ValueError, "spp: 100000000000000000000 is out of range"),
    (lambda: ao.render("wedge", CAM, seed=2 ** 40), ValueError, "seed: 1099511627776 is out of range [0, 4294967295]"),
    (lambda: ao.render("wedge", CAM, "gtao", slices=10 ** 30), ValueError, "slices: the integer"),
    (lambda: ao.Scene.from_arrays(V, [[0, 1, 10 ** 12]]), ValueError, "arrays: face 0 uses vertex 1000000000000"),
    (lambda: ao.render("wedge", CAM, radius=-1.0), ValueError, "radius must be a positive finite number of world units"),
    (lambda: ao.occlusion("plane", [[0, 0, 0]], [[0, 1, 0]], samples=0), ValueError, "raytraced: samples must be an integer in [1, 1048576], got 0"),
    # self-reference and deep nesting: an error, not a crash of the interpreter
    (lambda: ao.render("wedge", CAM, "gtao", slices=cyclic()), ValueError, "slices: nested deeper than 32 levels"),
    (lambda: ao.render("wedge", CAM, "gtao", slices=deep(100000)), ValueError, "slices: nested deeper than 32 levels"),
    (lambda: ao.render("wedge", {"eye": [deep(100000), 0, 0]}), TypeError, "camera.eye[0]: expected a number, got list"),
    (lambda: ao.compare("wedge", params={"gtao": {"slices": cyclic()}}), ValueError, "gtao.slices: nested deeper than 32 levels"),
    (lambda: ao._ao.check_camera({"eye": cyclic()}), ValueError, "camera.eye: nested deeper than 32 levels"),
]


@pytest.mark.parametrize("call,error,start", CASES, ids=[c[2][:40] for c in CASES])
def test_bad_input_names_the_argument(call, error, start, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(error) as e:
        call()
    text = str(e.value)
    assert text.startswith(start), text
    assert "\n" not in text and len(text) < 300, text
    for leak in ("std::", "json", "pybind", "Unregistered", "unsigned int", "basic_string"):
        assert leak not in text, text
    if error is ValueError:
        assert isinstance(e.value, ao.InputError)


def test_every_request_field_has_a_keyword_name():
    table = dict(ao._ao.keyword_table())
    assert set(table) == set(ao._ao.request_fields())
    # The fields ao's Python functions set have their keyword's name.
    for field, keyword in [("BakeRequest::padding", "padding"), ("RenderRequest::samples", "spp"), ("CameraRequest::width", "camera.width"),
                           ("FalloffRequest::radius", "radius"), ("BakeRequest::outputs.map", "output"), ("PointsRequest::points", "points")]:
        assert table[field] == keyword


def test_job_errors_name_keywords(tmp_path):
    scene = ao.Scene.from_arrays(V, F, uvs=T)
    with pytest.raises(ao.InputError, match=r"^padding must be in \[0, 1024\] texels, got 2000$"):
        ao.bake(scene, padding=2000)
    with pytest.raises(ao.InputError, match=r"^uv_set must be in \[0, 7\] \(UV sets count from 0\), got 9$"):
        ao.bake(scene, uv_set=9)
    with pytest.raises(ao.InputError, match=r"^spp: method gtao has no sample count$"):
        ao.render("wedge", CAM, "gtao", spp=4)


def test_docstrings_say_what_the_calls_do():
    # The examples in the docstrings run (doctest), and what they state about values holds.
    result = doctest.testmod(ao, extraglobs={"ao": ao}, optionflags=doctest.ELLIPSIS)
    assert result.failed == 0 and result.attempted >= 4, result
    # Render: 1 where no surface is seen (the module docstring).
    g = ao.render("sphere-on-plane", CAM, "volumetric", full=True)
    background = g["gbuffer"].object_id == 0
    assert background.any() and np.all(g["visibility"][background] == 1)
    # Bake: 0 beyond the charts and their padding, `mask` 1 on the covered texels.
    out = ao.bake(ao.Scene.from_arrays(V, F, uvs=T * 0.5), 32, padding=2, samples=4, full=True)
    assert out["mask"].dtype == np.uint8 and out["mask"].any() and not out["mask"].all()
    assert np.all(out["map"][:4, -4:] == 0)  # far from the chart in the lower left
    # Per-vertex AO of a mesh made from arrays, without UVs and without files.
    per_vertex = ao.bake(ao.Scene.from_arrays(V, F), map=False, per_vertex=True, samples=8)
    assert per_vertex.shape == (len(V),) and np.all((0 <= per_vertex) & (per_vertex <= 1))


@pytest.mark.parametrize("kwargs, suggestion", [
    ({"scene": "wedge", "method": "gtoa"}, "did you mean 'gtao'?"),
    ({"scene": "wedge", "method": "raytrace"}, "did you mean 'raytraced'?"),
    ({"scene": "wedge", "method": "gtao", "slcies": 4}, "did you mean 'slices'?"),
    ({"scene": "wedge", "method": "cone", "preset": "hihg"}, "did you mean 'high'?"),
    ({"scene": "wdge"}, "did you mean 'wedge'?"),
    ({"scene": "wedge", "membership": "stpe"}, "did you mean 'step'?"),
])
def test_a_mistyped_name_gets_the_closest_one(kwargs, suggestion):
    """As on the command line: methods, parameters, their values, scenes and memberships."""
    with pytest.raises(ao.InputError, match=re.escape(suggestion)):
        ao.render(camera=ao.Camera(width=8, height=5), **kwargs)


def test_a_name_far_from_every_known_one_gets_no_suggestion():
    with pytest.raises(ao.InputError) as e:
        ao.render("wedge", ao.Camera(width=8, height=5), method="sphere")
    assert "did you mean" not in str(e.value) and "unknown method 'sphere'" in str(e.value)
