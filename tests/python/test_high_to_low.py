# SPDX-License-Identifier: Apache-2.0
"""High to low without a cage or an extrusion: the default cage distance is fitted to the pair
(src/ao/bake/cage_fit.cpp), so a plain bake reaches the high mesh from almost every texel. The
pair is tests/bake/high_to_low_test.cpp's: a 24 x 12 lat-long unit sphere (low, UVs) and a 250 x
125 sphere with bumps r = 1 + 0.1 sin 8 phi sin 8 theta (high). A fixed 0.01 x the low diagonal
(0.035) reaches neither the bumps' tops (0.1 out) nor their valleys (0.1 in): 29,535 of 61,066
texels missed at 256^2."""

import warnings

import numpy as np
import pytest

import ao


def lat_long(segments, rings, radius, uvs):
    """tests/bake/high_to_low_test.cpp's lat_long_sphere: vertices, faces, uvs (u = phi / 2pi, v = 1 - theta / pi)."""
    theta, phi = np.meshgrid(np.pi * np.arange(rings + 1) / rings, 2 * np.pi * np.arange(segments + 1) / segments, indexing="ij")
    r = radius(theta, phi)
    v = np.stack([np.sin(theta) * np.cos(phi), np.cos(theta), -np.sin(theta) * np.sin(phi)], -1) * r[..., None]
    v[:, -1] = v[:, 0]  # the seam and the poles exactly shared, so the surface is watertight
    v[0], v[-1] = [0, r[0, 0], 0], [0, -r[-1, 0], 0]
    t = np.stack([phi / (2 * np.pi), 1 - theta / np.pi], -1)
    k = np.arange((rings + 1) * (segments + 1)).reshape(rings + 1, segments + 1)
    a, b, c, d = k[:-1, :-1], k[1:, :-1], k[1:, 1:], k[:-1, 1:]
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return v.reshape(-1, 3).astype(np.float32), faces, (t.reshape(-1, 2).astype(np.float32) if uvs else None)


def scene(segments, rings, radius, uvs, name):
    v, f, t = lat_long(segments, rings, radius, uvs)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the poles' degenerate triangles are dropped with a warning
        return ao.Scene.from_arrays(v, f, uvs=t, name=name)


@pytest.fixture(scope="module")
def low():
    return scene(24, 12, lambda t, p: np.ones_like(t), True, "low")


def plain_bake(low, high, **kwargs):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        s = ao.bake(low, 256, samples=16, high=high, full=True, **kwargs)["summary"]
    return s, [str(w.message) for w in caught]


def test_plain_bake_of_a_bumpy_pair_misses_under_one_percent(low):
    high = scene(250, 125, lambda t, p: 1 + 0.1 * np.sin(8 * p) * np.sin(8 * t), False, "high")
    s, warned = plain_bake(low, high)
    assert s["missed_texels"] < 0.01 * s["texels_covered"], s["missed_texels"]
    # The bumps reach 0.1 out and in; the low faces lie up to 1 - cos(pi / 24) = 0.0086 inside the unit sphere.
    assert 0.1 <= s["parameters"]["cage_extrusion"] <= 0.1 * 1.05 + 0.0086 + 0.01
    given, warned = plain_bake(low, high, cage_extrusion=0.035)  # what the fixed default gave
    assert given["missed_texels"] > 0.3 * given["texels_covered"]
    assert any("raise cage_extrusion (given: 0.035) or max_back" in w for w in warned), warned


def test_fitted_distance_is_the_gap_between_concentric_spheres(low):
    # A sphere of radius 1.3 around the low one: a point of the low surface needs 0.3 plus its depth
    # below the unit sphere, at most 1 - cos^2(pi / 24) = 0.017 (the plane of a lat-long quad spanning
    # pi / 12 both ways), less the high faces' own depth below 1.3; times the fit's 1.05.
    s, _ = plain_bake(low, scene(96, 48, lambda t, p: np.full_like(t, 1.3), False, "outer"))
    sag = 1 - np.cos(np.pi / 24) ** 2
    assert s["missed_texels"] == 0 and 0.3 * 1.05 <= s["parameters"]["cage_extrusion"] <= (0.3 + sag) * 1.05


def test_fitted_distance_is_never_below_the_fixed_fraction(low):
    # The high mesh is the low one: nothing to reach, so D stays 0.01 x the diagonal (2 sqrt 3).
    s, _ = plain_bake(low, low)
    assert s["parameters"]["cage_extrusion"] == pytest.approx(0.01 * 2 * np.sqrt(3), rel=1e-3) and s["missed_texels"] == 0


def test_a_cage_gets_advice_it_can_follow(low):
    high = scene(250, 125, lambda t, p: 1 + 0.1 * np.sin(8 * p) * np.sin(8 * t), False, "high")
    v, f, t = lat_long(24, 12, lambda t_, p: np.full_like(t_, 1.02), True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cage = ao.Scene.from_arrays(v, f, uvs=t, name="cage")
    _, warned = plain_bake(low, high, cage=cage)
    assert any("push cage further out, or raise max_front or max_back" in w for w in warned), warned
    assert not any("cage_extrusion" in w for w in warned)
