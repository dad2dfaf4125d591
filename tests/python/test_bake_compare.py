# SPDX-License-Identifier: Apache-2.0
"""ao.bake and ao.compare: arrays and tables equal `ao bake`'s and `ao compare`'s outputs for the
same inputs and seed (the same job functions run underneath, so equality is exact)."""

import json

import numpy as np
import pytest

import ao
from conftest import bumpy_grid, cli_error, read_ply_quality, run_cli, write_obj


def test_bake_map_equals_cli(ao_binary, grid_obj, tmp_path):
    out = tmp_path / "map.exr"
    run_cli(ao_binary, "bake", grid_obj, "-s", 48, "--spp", 16, "--seed", 5, "-o", out)
    m = ao.bake(grid_obj, size=48, samples=16, seed=5, full=True)
    assert m["map"].shape == (48, 48) and m["map"].dtype == np.float32
    np.testing.assert_array_equal(m["map"], ao.read_image(out))
    covered = m["mask"] != 0
    # The grid's bump occludes its surroundings; a flat open corner sees the whole hemisphere.
    assert covered.mean() > 0.9 and m["map"][covered].min() < 0.9 and m["map"][covered].max() == pytest.approx(1.0, abs=1e-6)


def test_bake_from_arrays_equals_the_file(grid_obj):
    vertices, faces, uvs = bumpy_grid()
    scene = ao.Scene.from_arrays(vertices, faces, uvs=uvs, name="grid")
    np.testing.assert_array_equal(ao.bake(scene, 32, samples=8), ao.bake(grid_obj, 32, samples=8))


def test_the_ao_family_equals_cli(ao_binary, grid_obj, tmp_path):
    paths = {k: tmp_path / f"{k}.exr" for k in ("map", "bent", "thickness", "cavity")}
    run_cli(ao_binary, "bake", grid_obj, "-s", 32, "--spp", 16, "--spread-angle", 140, "-o", paths["map"], "--bent-normals", paths["bent"],
            "--bent-normals-space", "tangent", "--thickness", paths["thickness"], "--thickness-distance", 0.2, "--cavity", paths["cavity"])
    m = ao.bake(grid_obj, 32, samples=16, spread_angle=140, bent_normals=True, bent_normals_space="tangent", thickness=True,
                thickness_distance=0.2, cavity=True)
    assert set(m) >= {"map", "mask", "bent_normals", "thickness", "cavity", "summary"}  # the family's flags return the full dict
    np.testing.assert_array_equal(m["map"], ao.read_image(paths["map"]))
    np.testing.assert_array_equal(m["thickness"], ao.read_image(paths["thickness"]))
    np.testing.assert_array_equal(m["cavity"], ao.read_image(paths["cavity"]))
    n = m["bent_normals"]
    assert n.shape == (32, 32, 3)
    encoded = np.where(np.any(n != 0, axis=-1, keepdims=True), n * np.float32(0.5) + np.float32(0.5), np.float32(0.5))
    np.testing.assert_array_equal(encoded, ao.read_image(paths["bent"], rgb=True))
    covered = m["mask"] != 0
    # A single-sided bumpy grid: nothing behind its flat parts (thickness 1), the grid's other side
    # within reach of rays into its slopes (below 1).
    assert m["thickness"][covered].max() == pytest.approx(1.0, abs=1e-6) and m["thickness"][covered].min() < 0.9
    # Cavity's R is shorter than the map's (unlimited): texel by texel the same rays, so unfiltered the
    # order is exact; the filter weighs each map by its own values, which moves a minimum by up to ~2e-4.
    assert m["cavity"][covered].min() >= m["map"][covered].min() - 1e-3
    u = ao.bake(grid_obj, 32, samples=16, spread_angle=140, cavity=True, denoise=0)
    assert np.all(u["cavity"][covered] >= u["map"][covered])
    with pytest.raises(ao.InputError, match="tangent"):
        ao.bake(grid_obj, 32, bent_normals_space="tangnet", bent_normals=True)


def test_texel_sampling_errors_name_what_the_caller_wrote(grid_obj):
    # texel_sampling is one of the baker's **params: a bad value names it and its choices, and
    # centre with per-vertex AO names the per-vertex bake, not an argument the caller did not pass.
    with pytest.raises(ao.InputError, match="texel_sampling.*area.*centre"):
        ao.bake(grid_obj, 16, texel_sampling="middle")
    with pytest.raises(ao.InputError, match="^texel_sampling centre is for maps: a vertex has no texel") as e:
        ao.bake(grid_obj, map=False, per_vertex=True, texel_sampling="centre")
    assert "per_vertex_output" not in str(e.value)
    assert ao.bake(grid_obj, 16, samples=4, texel_sampling="centre").shape == (16, 16)


def test_scene_tangents_are_unit_and_perpendicular(grid_obj):
    scene = ao.Scene.load(grid_obj)
    t = scene.tangents()
    assert t.shape == (3 * scene.triangles, 4) and t.dtype == np.float32
    np.testing.assert_allclose(np.linalg.norm(t[:, :3], axis=1), 1.0, atol=1e-5)
    assert set(np.unique(t[:, 3])) <= {-1.0, 1.0}
    with pytest.raises(ao.InputError, match="no UVs"):
        ao.Scene.from_arrays(*bumpy_grid()[:2]).tangents()


def test_high_to_low_from_arrays_equals_cli(ao_binary, tmp_path):
    # A flat low square takes the AO of a bumpy high grid over it: from ao.Scene objects made from
    # arrays (what the Blender add-on passes) and from the same meshes as files, with a cage made
    # from arrays and as a file (the low mesh lifted by 0.4), and with an extrusion.
    low_v, low_f, low_t = bumpy_grid(n=4, height=0.0)
    high_v, high_f, _ = bumpy_grid(n=24)
    cage_v = low_v + np.float32([0, 0.4, 0])
    files = [write_obj(tmp_path / name, v, f, t) for name, v, f, t in
             [("low.obj", low_v, low_f, low_t), ("high.obj", high_v, high_f, None), ("cage.obj", cage_v, low_f, low_t)]]
    low = ao.Scene.from_arrays(low_v, low_f, uvs=low_t, name="low")
    high = ao.Scene.from_arrays(high_v, high_f, name="high")
    cage = ao.Scene.from_arrays(cage_v, low_f, name="cage")
    for kwargs, args in [(dict(cage=cage), ["--cage", files[2]]), (dict(cage_extrusion=0.4, max_back=0.1), ["--cage-extrusion", 0.4, "--max-back", 0.1])]:
        out = tmp_path / "map.exr"
        run_cli(ao_binary, "bake", files[0], "--high", files[1], *args, "-s", 32, "--spp", 16, "-o", out)
        m = ao.bake(low, 32, samples=16, high=high, **kwargs)
        np.testing.assert_array_equal(m, ao.read_image(out))
        np.testing.assert_array_equal(ao.bake(files[0], 32, samples=16, high=[files[1]], **{**kwargs, "cage": kwargs.get("cage") and files[2]}), m)
        assert m.min() < 0.95 < m.max()  # the bump occludes its foot; the far corners are open
    with pytest.raises(ao.InputError, match="^high: mesh 0 has 625 vertices .* a cage must have the low mesh.s topology"):
        ao.bake(low, 32, high=high, cage=high)
    with pytest.raises(ao.InputError, match="^cage, cage_extrusion, max_front, max_back and .* need high"):
        ao.bake(low, 32, cage=cage)
    with pytest.raises(TypeError, match="cage: expected"):
        ao.bake(low, 32, high=high, cage=3)


def test_per_vertex_equals_cli(ao_binary, grid_obj, tmp_path):
    out = tmp_path / "v.ply"
    run_cli(ao_binary, "bake", grid_obj, "--spp", 16, "--per-vertex", out)
    values = ao.bake(grid_obj, map=False, per_vertex=True, samples=16)
    assert values.ndim == 1 and values.dtype == np.float32 and len(values) == 13 * 13
    np.testing.assert_array_equal(values, read_ply_quality(out))
    both = ao.bake(grid_obj, 16, per_vertex=True, samples=16)
    assert isinstance(both, tuple) and both[0].shape == (16, 16)
    np.testing.assert_array_equal(both[1], values)


def test_bake_errors_match_cli(ao_binary, grid_obj, tmp_path):
    # The same line, each naming the field its own way: the parameter table's name in both, the
    # request field as the keyword argument in Python and as the option on the command line.
    for kwargs, args, keyword, option in [(dict(samples=0), ["--spp", 0], "", ""), (dict(denoise=9), ["--denoise", 9], "", ""),
                                          (dict(size="0"), ["-s", 0], "size:", "--size:"),
                                          (dict(method="sideways"), ["-m", "sideways"], "method:", "--method:"),
                                          (dict(padding=2000), ["--padding", 2000], "padding must", "--padding must")]:
        with pytest.raises(ValueError) as e:
            ao.bake(grid_obj, **kwargs)
        cli = cli_error(ao_binary, "bake", grid_obj, *args, "-o", tmp_path / "unused.png")
        assert cli.startswith(option) and str(e.value).startswith(keyword), (cli, str(e.value))
        assert str(e.value) == keyword + cli[len(option):]
    with pytest.raises(ao.InputError, match="missing.obj"):
        ao.bake(tmp_path / "missing.obj")


def test_compare_rows_equal_cli_table(ao_binary, tmp_path):
    out = tmp_path / "cmp"
    run_cli(ao_binary, "compare", "sphere-on-plane", "--methods", "alchemy,volumetric", "--spp-reference", 16, "--width", 48,
            "--height", 27, "-p", "alchemy.samples=6", "--out-dir", out)
    with open(out / "table.json") as f:
        cli = json.load(f)["rows"]
    rows = ao.compare("sphere-on-plane", ao.Camera(width=48, height=27), ["alchemy", "volumetric"], spp_reference=16,
                      params={"alchemy": {"samples": 6}})
    assert [r["method"] for r in rows] == ["alchemy", "volumetric"]
    for mine, theirs in zip(rows, cli):
        assert _same_except_ms(mine, theirs), (mine, theirs)
        assert 0 < mine["rmse"] < 0.5 and mine["parameters"] == theirs["parameters"]


def _same_except_ms(a, b):
    """Equal but for run times, which are measured, wherever they are nested."""
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(k.endswith("ms") or _same_except_ms(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same_except_ms(x, y) for x, y in zip(a, b))
    return a == b


def test_compare_errors_match_cli(ao_binary, tmp_path):
    with pytest.raises(ValueError) as e:
        ao.compare("wedge", methods=["alchemy"], params={"alchemy": {"nosuch": 1}})
    cli = cli_error(ao_binary, "compare", "wedge", "--methods", "alchemy", "-p", "alchemy.nosuch=1", "--out-dir", tmp_path / "c")
    assert cli.startswith("--param: ") and str(e.value) == cli[len("--param: "):]
