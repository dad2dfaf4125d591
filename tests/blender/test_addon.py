# SPDX-License-Identifier: Apache-2.0
"""ao's Blender add-on, in Debian's Blender run headless (`blender -b`): the package installed with
`cmake --install --component python` into a temporary prefix, the add-on installed and enabled by
`python3 -m ao.blender install` into temporary user scripts and preferences folders
(BLENDER_USER_SCRIPTS, BLENDER_USER_CONFIG), then one Blender session (in_blender.py) bakes
Blender's own meshes with bpy.ops.object.ao_bake and writes the same meshes as OBJ files corner by
corner. Each image must equal `ao bake`'s map of those files with the same options, bit for bit:
the same triangles, vertices, normals and UVs in the same order give the same rays (src/ao/io/
obj_reader.h welds corners as the add-on does). Skipped, saying so, where blender is not installed.
"""

import json
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

import ao

HERE = os.path.dirname(os.path.abspath(__file__))
SIZE, SAMPLES = 128, 16  # as in_blender.py: a few seconds of baking in all


@pytest.fixture(scope="session")
def blender():
    path = shutil.which("blender")
    if path is None:
        pytest.skip("blender is not installed (Debian: apt-get install blender): the Blender add-on is not tested")
    return path


@pytest.fixture(scope="session")
def baked(blender, tmp_path_factory):
    """The add-on installed and enabled, the Blender session run: (its output folder, results.json)."""
    tmp = tmp_path_factory.mktemp("blender")
    prefix = tmp / "prefix"
    subprocess.run(["cmake", "--install", os.environ["AO_BUILD_DIR"], "--prefix", str(prefix), "--component", "python"], check=True,
                   capture_output=True)
    site = [os.path.join(d, "site-packages") for d, _, _ in os.walk(prefix) if os.path.isdir(os.path.join(d, "site-packages", "ao"))]
    assert len(site) == 1, f"no installed package ao under {prefix}"
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(BLENDER_USER_SCRIPTS=str(tmp / "scripts"), BLENDER_USER_CONFIG=str(tmp / "config"))
    os.environ["AO_TEST_SITE"] = site[0]  # for the uninstall test
    p = subprocess.run(["/usr/bin/python3", "-m", "ao.blender", "install", "--blender", blender], env=dict(env, PYTHONPATH=site[0]),
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stdout + p.stderr
    assert os.path.isfile(tmp / "scripts" / "addons" / "ao_bake.py"), p.stdout
    out = tmp / "out"
    out.mkdir()
    # No PYTHONPATH: Blender finds the package through the installed add-on file alone.
    q = subprocess.run([blender, "-b", "--python-exit-code", "1", "--python", os.path.join(HERE, "in_blender.py"), "--", str(out)], env=env,
                       capture_output=True, text=True, timeout=600)
    assert q.returncode == 0, q.stdout[-4000:] + q.stderr[-4000:]
    with open(out / "results.json") as f:
        return out, json.load(f)


def cli_map(tmp, *args):
    """`ao bake ARGS` into an EXR (floats as baked), read back."""
    path = os.path.join(tmp, "cli-" + str(abs(hash(args))) + ".exr")
    p = subprocess.run([os.environ["AO_BINARY"], "bake", *map(str, args), "-o", path, "-q"], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return ao.read_image(path)


def addon_map(out, case):
    """The red channel of the add-on's image, rows from the top as ao writes maps."""
    pixels = np.load(os.path.join(out, case + ".npy"))
    assert np.all(pixels[..., 0] == pixels[..., 1]) and np.all(pixels[..., 0] == pixels[..., 2]) and np.all(pixels[..., 3] == 1)
    return np.flipud(pixels[..., 0])


def assert_same(addon, cli, what):
    assert addon.shape == cli.shape, what
    diff = np.abs(addon.astype(np.float64) - cli)
    assert diff.max() <= 1e-6, f"{what}: {np.count_nonzero(diff > 1e-6)} of {diff.size} texels differ, up to {diff.max()}"


def test_addon_is_installed_and_enabled(baked):
    assert baked[1]["addon_enabled"]


def test_single_mesh_equals_ao_bake(baked):
    out, r = baked
    assert r["single"]["returned"] == ["FINISHED"]
    assert (r["single"]["width"], r["single"]["height"], r["single"]["float"], r["single"]["colorspace"]) == (SIZE, SIZE, True, "Non-Color")
    m = addon_map(out, "single")
    assert 0.3 < m.mean() < 0.9 and m.min() < 0.3  # Suzanne's eyes and creases are dark, her charts mostly open
    cli = cli_map(out, out / "low.obj", "--size", SIZE, "--samples", SAMPLES)
    assert_same(m, cli, "defaults")
    # The image as Blender saves it (8-bit PNG, Blender's own row order) shows the map upright:
    # the orientation does not rest on the flip the add-on and addon_map() both make.
    saved = ao.read_image(os.path.join(out, "single.png"))
    assert np.abs(saved - cli).max() <= 0.5 / 255 + 1e-6


def test_every_option_reaches_ao_bake(baked):
    out, r = baked
    assert r["options"]["returned"] == ["FINISHED"]
    cli = cli_map(out, out / "low.obj", "--size", SIZE, "--samples", SAMPLES, "--max-distance", 0.5, "--membership", "linear", "--denoise", 0,
                  "--padding", 3, "--seed", 7, "--ignore-back-faces")
    assert_same(addon_map(out, "options"), cli, "options")
    assert not np.array_equal(addon_map(out, "options"), addon_map(out, "single"))


def cli_family(tmp, *args):
    """`ao bake ARGS` with the AO family into EXRs: {map, bent (H x W x 3), thickness, cavity}."""
    paths = {k: os.path.join(tmp, f"cli-family-{k}.exr") for k in ("map", "bent", "thickness", "cavity")}
    p = subprocess.run([os.environ["AO_BINARY"], "bake", *map(str, args), "-o", paths["map"], "--bent-normals", paths["bent"], "--bent-normals-space",
                        "tangent", "--thickness", paths["thickness"], "--cavity", paths["cavity"], "-q"], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return {k: ao.read_image(v, rgb=(k == "bent")) for k, v in paths.items()}


def test_the_ao_family_equals_ao_bake(baked):
    out, r = baked
    assert r["family"]["returned"] == ["FINISHED"]
    cli = cli_family(out, out / "low.obj", "--size", SIZE, "--samples", SAMPLES, "--spread-angle", 150, "--thickness-distance", 0.3,
                     "--cavity-distance", 0.05)
    assert_same(addon_map(out, "family"), cli["map"], "AO with a 150-degree cone")
    for kind in ("thickness", "cavity"):
        pixels = np.load(os.path.join(out, f"family_{kind}.npy"))
        assert_same(np.flipud(pixels[..., 0]), cli[kind], kind)
    bent = np.flipud(np.load(os.path.join(out, "family_bent.npy"))[..., :3])
    assert_same(bent, cli["bent"], "bent normals, tangent space")
    # Tangent space: mostly along the normal (blue), leaning where Suzanne's creases close one side.
    assert 0.85 < bent[..., 2].mean() <= 1.0 and np.abs(bent[..., :2] - 0.5).max() > 0.2
    thickness = np.flipud(np.load(os.path.join(out, "family_thickness.npy"))[..., 0])
    assert thickness.min() < 0.5 < thickness.max()  # her ears are thin, her head is not


def test_tangent_frames_are_blenders(baked):
    out, _ = baked
    blender = np.load(os.path.join(out, "tri_tangents.npy"))
    ours = ao.Scene.load(str(out / "tri.obj")).tangents()
    assert ours.shape == blender.shape
    assert set(np.unique(blender[:, 3])) == {-1.0, 1.0}, "the test mesh should have mirrored and kept UV islands"
    np.testing.assert_array_equal(ours[:, 3], blender[:, 3])
    err = np.abs(ours[:, :3] - blender[:, :3]).max(axis=1)
    assert err.max() <= 1e-4, f"{np.count_nonzero(err > 1e-4)} of {len(err)} corners differ, up to {err.max()}"


def test_selected_to_active_equals_ao_bake_high(baked):
    out, r = baked
    assert r["high"]["returned"] == ["FINISHED"]
    cli = cli_map(out, out / "low.obj", "--high", out / "high.obj", "--size", SIZE, "--samples", SAMPLES, "--cage-extrusion", 0.02)
    assert_same(addon_map(out, "high"), cli, "high to low, extrusion")


def test_cage_object_equals_ao_bake_cage(baked):
    out, r = baked
    assert r["cage"]["returned"] == ["FINISHED"]
    cli = cli_map(out, out / "low.obj", "--high", out / "high.obj", "--cage", out / "cage.obj", "--max-back", 0.05, "--size", SIZE, "--samples", SAMPLES)
    assert_same(addon_map(out, "cage"), cli, "high to low, cage object")
    assert not np.array_equal(addon_map(out, "cage"), addon_map(out, "high"))


def test_bad_input_is_reported_and_leaves_no_image(baked):
    r = baked[1]
    assert "NoUV: the mesh has no UV map" in r["no_uv"]["error"] and not r["no_uv"]["image"]
    assert "cage High:" in r["bad_cage"]["error"] and "the active mesh has" in r["bad_cage"]["error"] and not r["bad_cage"]["image"]


def test_cancel_stops_within_a_second_and_leaves_no_image(baked):
    r = baked[1]["cancel"]
    assert r["returned"] == ["CANCELLED"] and not r["image"]
    assert r["seconds"] < 0.5 + 10  # cancelled at 0.5 s; stopped at its next progress report (the full bake takes over ten minutes)


@pytest.fixture(scope="session")
def window(baked, blender):
    """in_window.py's results: the operator run from a window (xvfb-run's virtual display)."""
    xvfb = shutil.which("xvfb-run")
    if xvfb is None:
        pytest.skip("xvfb-run is not installed (Debian: apt-get install xvfb): the modal operator and Esc are not tested")
    out = baked[0]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    # Blender saves quit.blend into its temporary folder when a window quits: the test's own, not /tmp.
    temp = out.parent / "blender-temp"
    temp.mkdir(exist_ok=True)
    env.update(BLENDER_USER_SCRIPTS=str(out.parent / "scripts"), BLENDER_USER_CONFIG=str(out.parent / "config"), TMPDIR=str(temp), TEMP=str(temp))
    q = subprocess.run([xvfb, "-a", "-s", "-screen 0 1280x800x24", blender, "--enable-event-simulate", str(out / "scene.blend"), "--python",
                        os.path.join(HERE, "in_window.py"), "--", str(out)], env=env, capture_output=True, text=True, timeout=600)
    assert q.returncode == 0 and os.path.exists(out / "window.json"), q.stdout[-4000:] + q.stderr[-4000:]
    if os.environ.get("AO_BLENDER_PICTURES"):  # docs/bake.md's picture: AO_BLENDER_PICTURES=docs/images
        shutil.copyfile(out / "window.png", os.path.join(os.environ["AO_BLENDER_PICTURES"], "blender-addon.png"))
    with open(out / "window.json") as f:
        return json.load(f)


def test_modal_bake_from_a_window(window):
    assert "timed_out" not in window and "error" not in window, window
    assert window["invoke"] == ["RUNNING_MODAL"]
    assert window["modal"]["size"] == [256, 256] and window["modal"]["float"]  # the panel's settings


def test_esc_cancels_a_modal_bake_and_leaves_no_image(window):
    assert "timed_out" not in window and "error" not in window, window
    assert window["invoke_long"] == ["RUNNING_MODAL"] and window["long_running"]
    assert not window["cancel"]["image"]
    # The thread ends well before the full bake would (over ten minutes); under the software renderer
    # and a loaded machine the window's event loop takes seconds to deliver Esc.
    assert window["cancel"]["seconds"] < 30


def test_uninstall_removes_and_disables_the_addon(baked, blender):
    # Last in the file: the other tests use the installed add-on.
    scripts, config = baked[0].parent / "scripts", baked[0].parent / "config"
    env = dict(os.environ, BLENDER_USER_SCRIPTS=str(scripts), BLENDER_USER_CONFIG=str(config), PYTHONPATH=os.environ["AO_TEST_SITE"])
    p = subprocess.run(["/usr/bin/python3", "-m", "ao.blender", "uninstall", "--blender", blender], env=env, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0 and not os.path.exists(scripts / "addons" / "ao_bake.py"), p.stdout + p.stderr
    q = subprocess.run([blender, "-b", "--python-expr", "import bpy; print('enabled:', 'ao_bake' in bpy.context.preferences.addons)"],
                       env={k: v for k, v in env.items() if k != "PYTHONPATH"}, capture_output=True, text=True, timeout=300)
    assert "enabled: False" in q.stdout, q.stdout
    bad = subprocess.run(["/usr/bin/python3", "-m", "ao.blender", "install", "--blender", str(baked[0] / "no-blender")], env=env,
                         capture_output=True, text=True, timeout=60)
    assert bad.returncode == 1 and "Blender not found" in bad.stderr
