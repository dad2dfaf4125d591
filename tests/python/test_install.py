# SPDX-License-Identifier: Apache-2.0
"""The module installs: `pip install --no-build-isolation .` into a virtual environment made from
Debian's python3 (with its system packages: numpy), without network (--no-index), through the
in-tree build backend (python/build_backend/); the backend reuses the test's build folder, so this
checks the packaging, not a second compile. The installed package carries its type stubs
(PEP 561). `pip install -e .` installs the distribution "ao" whose package is the build folder's,
so an edit of python/ao/*.py is live."""

import os
import subprocess
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


@pytest.fixture
def venv(tmp_path):
    path = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", str(path)], check=True)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(AO_PIP_BUILD_DIR=os.environ["AO_BUILD_DIR"], PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1")
    return str(path / "bin" / "python"), env


def pip_install(python, env, *args):
    p = subprocess.run([python, "-m", "pip", "install", "--no-build-isolation", "--no-index", *args], env=env, capture_output=True,
                       text=True, timeout=900)
    assert p.returncode == 0, p.stdout + p.stderr


def run(python, env, code, cwd):
    q = subprocess.run([python, "-c", code], env=env, cwd=cwd, capture_output=True, text=True)
    assert q.returncode == 0, q.stderr
    return q.stdout.split("\n")


def test_pip_install_into_venv(venv, tmp_path):
    python, env = venv
    pip_install(python, env, ROOT)
    code = ("import ao, os; print(ao.__file__); print(ao.render('wedge', ao.Camera(width=16, height=9), 'volumetric').shape); "
            "d = os.path.dirname(ao.__file__); print(sorted(f for f in os.listdir(d) if f.endswith('.pyi') or f == 'py.typed'))")
    path, shape, stubs = run(python, env, code, tmp_path)[:3]
    assert path.startswith(str(tmp_path / "venv")) and shape == "(9, 16)"
    assert stubs == "['__init__.pyi', '_ao.pyi', 'batch.pyi', 'py.typed']"


def test_pip_install_editable(venv, tmp_path):
    python, env = venv
    pip_install(python, env, "-e", ROOT)
    code = "import ao, importlib.metadata as m; print(ao.__file__); print(m.version('ao'))"
    path, version = run(python, env, code, tmp_path)[:2]
    assert os.path.realpath(path) == os.path.join(ROOT, "python", "ao", "__init__.py")  # the source, through the build folder
    assert path.startswith(os.environ["AO_BUILD_DIR"]) and version == run(python, env, "import ao; print(ao.__version__)", tmp_path)[0]
