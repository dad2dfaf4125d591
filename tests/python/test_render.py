# SPDX-License-Identifier: Apache-2.0
"""ao.render, ao.gbuffer and the caller's own G-buffer: the arrays equal `ao render`'s output for
the same inputs and seed (both run the job layer's run_render, so equality is exact: the same
floats, written to EXR as 32-bit floats and read back unchanged)."""

import numpy as np
import pytest

import ao
from conftest import bumpy_grid, cli_error, run_cli, write_obj

SIZE = dict(width=64, height=36)


def cli_render(binary, tmp_path, *args):
    out = tmp_path / "cli.exr"
    run_cli(binary, "render", *args, "--width", SIZE["width"], "--height", SIZE["height"], "-o", out)
    return ao.read_image(out)


def test_raytraced_equals_cli_and_returns_its_standard_error(ao_binary, tmp_path):
    cli = cli_render(ao_binary, tmp_path, "wedge", "--spp", 16, "--seed", 7)
    out = ao.render("wedge", ao.Camera(**SIZE), spp=16, seed=7, full=True)
    v = out["visibility"]
    assert v.dtype == np.float32 and v.shape == (36, 64)
    np.testing.assert_array_equal(v, cli)
    err = out["std_error"]
    assert err.shape == v.shape and err.dtype == np.float32
    covered = out["gbuffer"].object_id != 0
    # 16 rays of a 0/1 visibility: the sample standard deviation (n - 1 in the denominator) is at
    # most sqrt(0.25 * 16 / 15), so the standard error of the mean is at most 0.5 / sqrt(15).
    assert np.all(err >= 0) and np.all(err <= 0.5 / np.sqrt(15) + 1e-6)
    assert np.all(err[~covered] == 0) and np.any(err[covered] > 0)
    assert out["summary"]["method"] == "raytraced" and out["summary"]["parameters"]["samples"] == 16


@pytest.mark.parametrize("method,params,cli_params", [
    ("volumetric", {}, []),
    ("alchemy", {"samples": 8, "contrast": 1.5}, ["-p", "samples=8", "-p", "contrast=1.5"]),
    ("gtao", {"slices": 3}, ["-p", "slices=3"]),
])
def test_screen_space_methods_equal_cli(ao_binary, tmp_path, method, params, cli_params):
    cli = cli_render(ao_binary, tmp_path, "sphere-on-plane", "-m", method, "--seed", 3, "--radius", 0.4, *cli_params)
    v = ao.render("sphere-on-plane", ao.Camera(**SIZE), method, seed=3, radius=0.4, **params)
    np.testing.assert_array_equal(v, cli)


def test_files_and_arrays_make_the_same_scene(ao_binary, tmp_path):
    vertices, faces, uvs = bumpy_grid()
    obj = write_obj(tmp_path / "grid.obj", vertices, faces, uvs)
    cam = ao.Camera(eye=(1.6, 1.2, 1.8), target=(0.5, 0.1, 0.5), fov=40, **SIZE)
    cli = cli_render(ao_binary, tmp_path, obj, "--spp", 8, "--eye", "1.6,1.2,1.8", "--target", "0.5,0.1,0.5", "--fov", 40)
    scene = ao.Scene.from_arrays(vertices, faces, uvs=uvs, name="grid")
    assert scene.triangles == len(faces) and scene.vertices == len(vertices)
    np.testing.assert_array_equal(ao.render(obj, cam, spp=8), cli)
    np.testing.assert_array_equal(ao.render(scene, cam, spp=8), cli)


def test_camera_json_round_trip_matches_cli(ao_binary, tmp_path):
    # Values a float holds exactly: the file keeps the camera's floats.
    cam = ao.Camera(eye=[3.0, 2.0, 4.0], target=[0.0, 0.25, 0.0], up=[0.0, 1.0, 0.0], fov=35.0, **SIZE)
    path = tmp_path / "cam.json"
    cam.write(path)
    assert ao.Camera.read(path) == cam
    out = tmp_path / "cli.exr"
    run_cli(ao_binary, "render", "wedge", "--camera", path, "-m", "volumetric", "-o", out)
    np.testing.assert_array_equal(ao.render("wedge", path, "volumetric"), ao.read_image(out))


def test_own_gbuffer_equals_internal_one():
    cam = ao.Camera(**SIZE)
    g = ao.gbuffer("sphere-on-plane", cam)
    assert g.normal.shape == (36, 64, 3) and g.depth.shape == (36, 64) and not g.normal.flags.writeable
    for method in ("alchemy", "gtao", "volumetric"):
        internal = ao.render("sphere-on-plane", cam, method, radius=0.4)
        np.testing.assert_array_equal(ao.render(gbuffer=g, method=method, radius=0.4), internal)
        # The caller's arrays, as another renderer would hand them over: positions and normals in
        # camera space, albedo, ids, the camera's projection and placement.
        own = ao.gbuffer_from_arrays(np.array(g.normal), position=np.array(g.position), albedo=np.array(g.albedo),
                                     object_id=np.array(g.object_id), camera=g.camera)
        np.testing.assert_array_equal(ao.render(gbuffer=own, method=method, radius=0.4), internal)


def test_arrays_without_a_scene_take_sheets_of_a_thickness():
    # Arrays from another renderer bring no scene to trace a second depth layer from: layers=2 is
    # refused, and thickness (one layer's surfaces as sheets, docs/methods/depth-layers.md) runs as it
    # does on the scene's own G-buffer, freeing space behind the surfaces that one layer takes for solid.
    cam = ao.Camera(**SIZE)
    g = ao.gbuffer("default", cam)
    own = ao.gbuffer_from_arrays(np.array(g.normal), position=np.array(g.position), albedo=np.array(g.albedo),
                                 object_id=np.array(g.object_id), camera=g.camera)
    with pytest.raises(ao.InputError, match="layers=2 traces the second depth layer in the scene"):
        ao.render(gbuffer=own, method="containment", radius=1.5, layers=2)
    for method in ("containment", "volumetric", "transfer"):
        sheets = ao.render(gbuffer=own, method=method, radius=1.5, thickness=0.4)
        np.testing.assert_array_equal(sheets, ao.render("default", cam, method, radius=1.5, thickness=0.4))
        assert (sheets > ao.render(gbuffer=own, method=method, radius=1.5)).any(), method


def test_own_depth_buffer_agrees_with_positions():
    cam = ao.Camera(**SIZE)
    g = ao.gbuffer("sphere-on-plane", cam)
    internal = ao.render(gbuffer=g, method="gtao", radius=0.4)
    depth = np.where(g.object_id != 0, g.depth, np.inf).astype(np.float32)
    own = ao.gbuffer_from_arrays(g.normal, depth=depth, camera={"fov": g.camera["fov"]})
    assert np.array_equal(own.object_id != 0, g.object_id != 0)
    # Positions rebuilt from depth through the pixel centres differ from the rasterised ones by
    # float rounding (relative 1e-6 of the depth); GTAO's horizon angles move by as little, so V
    # agrees to 1e-4 (a tenth of an 8-bit grey level).
    np.testing.assert_allclose(ao.render(gbuffer=own, method="gtao", radius=0.4), internal, atol=1e-4)


def test_bad_parameters_raise_value_error_with_the_cli_text(ao_binary):
    # The CLI's line, with its option named as the keyword argument where the line names one.
    cases = [
        (dict(method="alchemy", foo=1), ["wedge", "-m", "alchemy", "-p", "foo=1"], "", "--param: "),
        (dict(method="gtao", slices=0), ["wedge", "-m", "gtao", "-p", "slices=0"], "", ""),
        (dict(spp=0), ["wedge", "--spp", 0], "", ""),
        (dict(method="nosuch"), ["wedge", "-m", "nosuch"], "", ""),
        (dict(membership="cubicle"), ["wedge", "--membership", "cubicle"], "membership:", "--membership:"),
        (dict(radius=-1.0), ["wedge", "--radius", -1], "radius must", "--radius must"),
    ]
    for kwargs, args, keyword, option in cases:
        with pytest.raises(ValueError) as e:
            ao.render("wedge", ao.Camera(**SIZE), **kwargs)
        assert isinstance(e.value, ao.InputError)
        cli = cli_error(ao_binary, "render", *args, "-o", "unused.exr")
        assert cli.startswith(option) and str(e.value) == keyword + cli[len(option):], (str(e.value), cli)


def test_bad_files_raise_input_error_naming_the_file(ao_binary, tmp_path):
    missing = tmp_path / "missing.obj"
    broken = tmp_path / "broken.obj"
    broken.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")
    for path in (missing, broken):
        with pytest.raises(ao.InputError) as e:
            ao.render(path, ao.Camera(**SIZE))
        assert str(path) in str(e.value)
        assert str(e.value) == cli_error(ao_binary, "render", path, "-o", tmp_path / "unused.exr")
    with pytest.raises(ao.InputError, match="grid: face 1 uses vertex 99"):
        ao.Scene.from_arrays(np.zeros((3, 3)), [[0, 1, 2], [0, 1, 99]], name="grid")
    with pytest.raises(ao.InputError, match="normal: expected an array of shape H x W x 3"):
        ao.gbuffer_from_arrays(np.zeros((4, 4)), depth=np.ones((4, 4)), camera={"fov": 40})


def test_io_failure_raises_os_error(tmp_path):
    # A file size limit makes the write fail as a full disk does (EFBIG); in a child process, so
    # the limit and the ignored SIGXFSZ do not reach the test run.
    import subprocess
    import sys
    code = (
        "import resource, signal, ao\n"
        "signal.signal(signal.SIGXFSZ, signal.SIG_IGN)\n"
        "resource.setrlimit(resource.RLIMIT_FSIZE, (1000, resource.RLIM_INFINITY))\n"
        "try:\n"
        f"    ao.render('wedge', ao.Camera(width=64, height=36), 'volumetric', output={str(tmp_path / 'v.exr')!r})\n"
        "except OSError as e:\n"
        "    print('OSError', type(e).__name__, e)\n"
    )
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert p.stdout.startswith("OSError OSError "), p.stdout + p.stderr
    assert "v.exr" in p.stdout
    assert list(tmp_path.iterdir()) == []  # the failed transaction leaves no file


def test_methods_lists_every_parameter_table(ao_binary, tmp_path):
    import json
    methods = {m["name"]: m for m in ao.methods()}
    assert {"raytraced", "containment", "volumetric", "transfer", "cone", "alchemy", "gtao"} <= set(methods)
    for name in ("raytraced", "alchemy"):
        p = run_cli(ao_binary, "render", "wedge", "-m", name, "--width", 8, "--height", 8, "--spp", 4, "--json", "-o", tmp_path / "v.exr")
        cli = json.loads(p.stdout)["parameters"]
        table = {s["name"]: s for s in methods[name]["params"]}
        assert set(table) == set(cli)
        for spec in table.values():
            assert spec["help"] and spec["type"] in ("int", "float", "bool", "enum", "int or None", "float or None")
    assert "alchemy: " in ao.render.__doc__ and "contrast=" in ao.render.__doc__
