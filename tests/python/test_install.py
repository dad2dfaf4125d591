"""The module installs: `pip install --no-build-isolation .` into a virtual environment made from
Debian's python3 (with its system packages: numpy), without network (--no-index), through the
in-tree build backend (python/build_backend/); the backend reuses the test's build folder, so this
checks the packaging, not a second compile."""

import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def test_pip_install_into_venv(tmp_path):
    build_dir = os.environ["AO_BUILD_DIR"]
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)], check=True)
    python = str(venv / "bin" / "python")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(AO_PIP_BUILD_DIR=build_dir, PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1")
    p = subprocess.run([python, "-m", "pip", "install", "--no-build-isolation", "--no-index", ROOT], env=env, capture_output=True,
                       text=True, timeout=900)
    assert p.returncode == 0, p.stdout + p.stderr
    code = "import ao; print(ao.__file__); print(ao.render('wedge', ao.Camera(width=16, height=9), 'volumetric').shape)"
    q = subprocess.run([python, "-c", code], env=env, cwd=tmp_path, capture_output=True, text=True)
    assert q.returncode == 0, q.stderr
    path, shape = q.stdout.split("\n")[:2]
    assert path.startswith(str(venv)) and shape == "(9, 16)"
