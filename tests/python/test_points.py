# SPDX-License-Identifier: Apache-2.0
"""ao.occlusion (AO at given points) against `ao render`'s ray-traced reference at the same points,
and the progress of long calls reaching Python: a callable, a tqdm bar, lines on stderr."""

import sys
import types

import numpy as np
import pytest

import ao

CAM = ao.Camera(width=48, height=27)


def world_points(gbuffer):
    """The G-buffer's camera-space positions and normals in world space (docs/gbuffer.md: right
    handed, looking down -z, so camera z is minus the viewing direction)."""
    c = gbuffer.camera
    eye, target, up = (np.array(c[k], dtype=np.float64) for k in ("eye", "target", "up"))
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    basis = np.stack([right, true_up, -forward])  # rows: camera x, y, z in world space
    return eye + gbuffer.position.astype(np.float64) @ basis, gbuffer.normal.astype(np.float64) @ basis


def test_occlusion_agrees_with_the_render_reference_at_the_same_points():
    out = ao.render("default", CAM, spp=256, seed=3, full=True)
    g = out["gbuffer"]
    covered = np.argwhere(g.object_id != 0)
    pick = covered[np.linspace(0, len(covered) - 1, 80).astype(int)]
    positions, normals = world_points(g)
    points = positions[pick[:, 0], pick[:, 1]]
    n = normals[pick[:, 0], pick[:, 1]]
    mine = ao.occlusion("default", points, n, samples=256, full=True)
    v, err = mine["visibility"], mine["std_error"]
    assert v.dtype == np.float32 and v.shape == (80,) and np.all((0 <= v) & (v <= 1))
    ref, ref_err = out["visibility"][pick[:, 0], pick[:, 1]], out["std_error"][pick[:, 0], pick[:, 1]]
    # Two independent estimates of the same V (different sample sets): their difference has the
    # standard deviation sqrt(s1^2 + s2^2); 4 of them, plus a standard error's floor of 1/256 for a
    # point whose rays all agreed (s = 0), bound it at every point but with probability < 1e-3 over
    # 80 points.
    bound = 4 * np.sqrt(err ** 2 + ref_err ** 2 + 2 * (1 / 256) ** 2)
    assert np.all(np.abs(v - ref) <= bound), np.max(np.abs(v - ref) / bound)
    assert 0.05 < np.mean(1 - ref)  # the points see some occlusion: the comparison is not of ones
    # The means over the points agree within 4 standard errors of the mean difference.
    assert abs(np.mean(v) - np.mean(ref)) <= 4 * np.sqrt(np.sum(err ** 2 + ref_err ** 2)) / len(v) + 1e-3
    assert mine["summary"]["rays"] == 80 * 256 and mine["summary"]["radius"] == pytest.approx(out["summary"]["radius"])  # the same default R


def test_occlusion_known_answers_and_seeds():
    # Above an open plane nothing occludes; under a 45 degree wedge crease... the plane: exactly 1.
    assert np.all(ao.occlusion("plane", [[0, 0, 0], [0.2, 0, 0.1]], [[0, 1, 0], [0, 2, 0]], samples=64) == 1)
    a = ao.occlusion("sphere-on-plane", [[0.6, 0.0, 0.0]], [[0, 1, 0]], samples=64, radius=0.5, seed=1)
    b = ao.occlusion("sphere-on-plane", [[0.6, 0.0, 0.0]], [[0, 1, 0]], samples=64, radius=0.5, seed=1)
    c = ao.occlusion("sphere-on-plane", [[0.6, 0.0, 0.0]], [[0, 1, 0]], samples=64, radius=0.5, seed=2)
    assert a[0] == b[0] and 0 < a[0] < 1 and a[0] != c[0]


def test_progress_goes_to_a_callable():
    calls = []
    ao.render("wedge", CAM, spp=16, progress=lambda stage, done, total: calls.append((stage, done, total)))
    assert calls and all(isinstance(s, str) and 0 <= d <= t for s, d, t in calls), calls
    assert calls[-1][0] == "raytraced" and calls[-1][1] == calls[-1][2] > 0  # the last call: the last stage, done

    def stop(stage, done, total):
        raise RuntimeError("enough")
    with pytest.raises(RuntimeError, match="enough"):
        ao.render("wedge", ao.Camera(width=320, height=180), spp=256, progress=stop)


def test_progress_true_shows_a_tqdm_bar_or_lines(monkeypatch, capfd):
    bars = []

    class FakeBar:
        def __init__(self, total=None, desc=None, leave=True):
            self.total, self.desc, self.n, self.closed = total, desc, 0, False
            bars.append(self)

        def update(self, k):
            self.n += k

        def close(self):
            self.closed = True

    tqdm = types.ModuleType("tqdm")
    tqdm.auto = types.ModuleType("tqdm.auto")
    tqdm.auto.tqdm = FakeBar
    monkeypatch.setitem(sys.modules, "tqdm", tqdm)
    monkeypatch.setitem(sys.modules, "tqdm.auto", tqdm.auto)
    ao.render("wedge", CAM, spp=16, progress=True)
    assert [b.desc for b in bars][-1] == "raytraced" and all(b.closed for b in bars)
    assert bars[-1].n == bars[-1].total > 0

    monkeypatch.setitem(sys.modules, "tqdm.auto", None)  # not installed: lines on stderr
    ao.render("wedge", CAM, spp=16, progress=True)
    assert "ao: raytraced 100%" in capfd.readouterr().err
