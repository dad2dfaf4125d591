# SPDX-License-Identifier: Apache-2.0
"""Shared pieces of the Python module's tests: the ao binary they compare against (AO_BINARY, set
by ctest), tiny generated meshes (the project's tests use only what they generate or carry), and
readers of the CLI's outputs."""

import os
import struct
import subprocess

import numpy as np
import pytest

import ao


@pytest.fixture(scope="session")
def ao_binary():
    path = os.environ.get("AO_BINARY")
    if not path or not os.access(path, os.X_OK):
        pytest.fail("AO_BINARY must name the ao binary (ctest sets it)")
    return path


def run_cli(binary, *args, check=True):
    """Runs `ao ARGS...` quietly; returns the CompletedProcess (stderr as text)."""
    p = subprocess.run([binary, *map(str, args), "-q"], capture_output=True, text=True)
    if check and p.returncode != 0:
        raise AssertionError(f"ao {' '.join(map(str, args))} failed ({p.returncode}): {p.stderr}")
    return p


def cli_error(binary, *args):
    """The one line `ao ARGS...` prints after "ao: error: " (exit code 1, bad input)."""
    p = run_cli(binary, *args, check=False)
    assert p.returncode == 1, (p.returncode, p.stderr)
    lines = [line for line in p.stderr.splitlines() if line.startswith("ao: error: ")]
    assert len(lines) == 1, p.stderr
    return lines[0][len("ao: error: "):]


def bumpy_grid(n=12, height=0.35, seed=0):
    """A unit square of n x n quads in x-z, y up, with a bump in the middle (and a little
    seed-dependent tilt, so meshes of a folder differ): vertices, faces, uvs (one chart, the
    square's own x-z), so its AO map is not constant."""
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    x, z = i / n, j / n
    r2 = (x - 0.5) ** 2 + (z - 0.5) ** 2
    y = height * np.exp(-r2 / 0.02) + 0.05 * seed * x
    vertices = np.stack([x, y, z], axis=-1).reshape(-1, 3).astype(np.float32)
    uvs = np.stack([x, z], axis=-1).reshape(-1, 2).astype(np.float32)
    faces = []
    for a in range(n):
        for b in range(n):
            v00, v10, v01, v11 = a * (n + 1) + b, (a + 1) * (n + 1) + b, a * (n + 1) + b + 1, (a + 1) * (n + 1) + b + 1
            faces += [(v00, v01, v11), (v00, v11, v10)]  # counter-clockwise seen from +y
    return vertices, np.array(faces, dtype=np.int64), uvs


def write_obj(path, vertices, faces, uvs=None):
    with open(path, "w") as f:
        for v in vertices:
            f.write("v %.9g %.9g %.9g\n" % tuple(v))
        if uvs is not None:
            for t in uvs:
                f.write("vt %.9g %.9g\n" % tuple(t))
        for t in faces + 1:
            f.write("f " + " ".join(f"{k}/{k}" if uvs is not None else str(k) for k in t) + "\n")
    return path


@pytest.fixture
def grid_obj(tmp_path):
    v, f, t = bumpy_grid()
    return write_obj(tmp_path / "grid.obj", v, f, t)


def read_ply_quality(path):
    """The per-vertex `quality` floats of a binary little-endian PLY (ply_export.h's layout)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    assert "format binary_little_endian 1.0" in header
    count, props, in_vertex = 0, [], False
    sizes = {"float": "f", "uchar": "B", "double": "d", "int": "i", "uint": "I"}
    for line in header:
        w = line.split()
        if w[0] == "element":
            in_vertex = w[1] == "vertex"
            count = int(w[2]) if in_vertex else count
        elif w[0] == "property" and in_vertex:
            props.append((w[-1], sizes[w[1]]))
    fmt = "<" + "".join(t for _, t in props)
    q = [n for n, _ in props].index("quality")
    size = struct.calcsize(fmt)
    return np.array([struct.unpack_from(fmt, data, end + k * size)[q] for k in range(count)], dtype=np.float32)


@pytest.fixture(autouse=True)
def _dask_files_in_tmp(tmp_path, monkeypatch):
    """Dask workers (the tests' and --local ones) keep their scratch space in the test's folder."""
    monkeypatch.setenv("DASK_TEMPORARY_DIRECTORY", str(tmp_path / "dask-scratch"))


@pytest.fixture(autouse=True)
def _one_thread_per_test():
    """All cores again after a test that limited them."""
    yield
    ao.set_threads(0)
