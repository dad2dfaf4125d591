# SPDX-License-Identifier: Apache-2.0
"""A PEP 517 build backend for the Python module ao that needs nothing outside Debian's packages.

`pip install --no-build-isolation .` calls build_wheel here: it configures and builds the project
with CMake (AO_PYTHON=ON, the interpreter running pip as Python_EXECUTABLE, so a virtual
environment's module matches its Python), installs the `python` component into a staging folder
and packs that folder as a wheel. No setuptools, no network: only the standard library, cmake and
the compiler. `pip install -e .` (build_editable, PEP 660) builds the module the same way and
installs a path file naming the build folder's python/ (its ao/ holds the compiled module and
symbolic links to python/ao/*.py), so edits to the Python files are live and a change to the C++
takes a rebuild (`cmake --build BUILD --target ao_python`). Source distributions are not offered.

Settings (pip --config-settings KEY=VALUE, or the environment variable in brackets):
  build-dir   [AO_PIP_BUILD_DIR]  the CMake build folder; default build-pip/ in the source tree.
              An existing build folder (e.g. build/) is reused as it is configured, rebuilding
              only what changed.
  jobs        [AO_PIP_JOBS]       parallel compile jobs; default all cores.
"""

import base64
import hashlib
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import zipfile

_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _version():
    with open(os.path.join(_ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        m = re.search(r"project\(ao VERSION ([0-9.]+)", f.read())
    if not m:
        raise RuntimeError("ao_build_backend: no version in CMakeLists.txt's project()")
    return m.group(1)


def _setting(config_settings, key, env):
    value = (config_settings or {}).get(key) or os.environ.get(env)
    return value or None


def _tag():
    impl = sys.implementation.cache_tag.replace("cpython-", "cp")  # cp311
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return f"{impl}-{impl}-{platform}"


def _metadata(version):
    return (f"Metadata-Version: 2.1\nName: ao\nVersion: {version}\n"
            "Summary: Ambient occlusion on the CPU: six published methods and a ray-traced ground truth\n"
            "Requires-Python: >=3.9\nRequires-Dist: numpy\n")


def get_requires_for_build_wheel(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    info = f"ao-{_version()}.dist-info"
    os.makedirs(os.path.join(metadata_directory, info), exist_ok=True)
    with open(os.path.join(metadata_directory, info, "METADATA"), "w", encoding="utf-8") as f:
        f.write(_metadata(_version()))
    return info


def _run(cmd):
    print("ao_build_backend:", " ".join(cmd), file=sys.stderr, flush=True)
    subprocess.run(cmd, check=True, stdout=sys.stderr)


def _build_dir(config_settings):
    return os.path.abspath(_setting(config_settings, "build-dir", "AO_PIP_BUILD_DIR") or os.path.join(_ROOT, "build-pip"))


def _compile(config_settings):
    """Configures (once) and builds the module and the package folder; returns the build folder."""
    build_dir = _build_dir(config_settings)
    jobs = _setting(config_settings, "jobs", "AO_PIP_JOBS") or str(os.cpu_count() or 1)
    if not os.path.exists(os.path.join(build_dir, "CMakeCache.txt")):
        cmd = ["cmake", "-S", _ROOT, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release", "-DAO_PYTHON=ON",
               f"-DPython_EXECUTABLE={sys.executable}"]
        if shutil.which("ninja"):
            cmd += ["-G", "Ninja"]
        if shutil.which("ccache"):
            cmd += ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache"]
        _run(cmd)
    _run(["cmake", "--build", build_dir, "-j", jobs, "--target", "ao_python"])
    return build_dir


def _build(config_settings, stage):
    _run(["cmake", "--install", _compile(config_settings), "--component", "python", "--prefix", stage])


def _record_line(path, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{path},sha256={digest},{len(data)}"


def _write_wheel(wheel_directory, version, files):
    """A wheel of `files` ({path in the wheel: bytes}) with its metadata and record."""
    info = f"ao-{version}.dist-info"
    files = dict(files)
    files[f"{info}/METADATA"] = _metadata(version).encode()
    files[f"{info}/WHEEL"] = (f"Wheel-Version: 1.0\nGenerator: ao_build_backend\nRoot-Is-Purelib: false\nTag: {_tag()}\n").encode()
    record = [_record_line(p, d) for p, d in files.items()] + [f"{info}/RECORD,,"]
    files[f"{info}/RECORD"] = ("\n".join(record) + "\n").encode()
    wheel = f"ao-{version}-{_tag()}.whl"
    with zipfile.ZipFile(os.path.join(wheel_directory, wheel), "w", zipfile.ZIP_DEFLATED) as z:
        for path, data in files.items():
            entry = zipfile.ZipInfo(path, date_time=(1980, 1, 1, 0, 0, 0))
            entry.external_attr = (0o755 if path.endswith(".so") else 0o644) << 16
            z.writestr(entry, data, zipfile.ZIP_DEFLATED)
    return wheel


def get_requires_for_build_editable(config_settings=None):
    return []


def prepare_metadata_for_build_editable(metadata_directory, config_settings=None):
    return prepare_metadata_for_build_wheel(metadata_directory, config_settings)


def build_editable(wheel_directory, config_settings=None, metadata_directory=None):
    """PEP 660: a wheel holding only ao-editable.pth, the build folder's python/ on sys.path."""
    build_dir = _compile(config_settings)
    package = os.path.join(build_dir, "python")
    if not os.path.isfile(os.path.join(package, "ao", "__init__.py")):
        raise RuntimeError(f"ao_build_backend: {package}/ao has no __init__.py after the build")
    return _write_wheel(wheel_directory, _version(), {"ao-editable.pth": (package + "\n").encode()})


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    version = _version()
    with tempfile.TemporaryDirectory(prefix="ao-wheel-") as stage:
        _build(config_settings, stage)
        package = None
        for dirpath, _, filenames in os.walk(stage):
            if os.path.basename(dirpath) == "ao" and "__init__.py" in filenames:
                package = dirpath
        if package is None:
            raise RuntimeError("ao_build_backend: cmake --install put no package ao into the staging folder")
        files = {}
        for name in sorted(os.listdir(package)):
            if name == "__pycache__":
                continue
            with open(os.path.join(package, name), "rb") as f:
                files[f"ao/{name}"] = f.read()
        return _write_wheel(wheel_directory, version, files)
