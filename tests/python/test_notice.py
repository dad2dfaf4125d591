# SPDX-License-Identifier: Apache-2.0
"""NOTICE against what is built: every shared library the ao command and the Python module link
(their ELF NEEDED entries), every library compiled in from headers, every package the module
imports is named, in a run-time section that fits who uses it; nothing they use is listed as tests
only, and no section is of another kind."""

import pathlib
import re
import subprocess

import pytest

import ao

ROOT = pathlib.Path(__file__).resolve().parents[2]

# The sections NOTICE has, by the start of their heading.
LIBAO, CLI_ONLY, PYTHON, TESTS = "Run time: linked by the library", "Run time: the ao command only", "Run time: the Python module", "Tests and benchmarks only"

# A linked library (the start of its soname) -> the name NOTICE gives it.
SONAMES = {
    "libembree3.": "Embree 3", "libtbb.": "oneTBB", "libhwy.": "Highway", "libassimp.": "assimp",
    "libOpenEXR": "OpenEXR", "libIex": "OpenEXR", "libIlmThread": "OpenEXR", "libImath": "Imath",
    "libpng16.": "libpng", "libz.": "zlib", "libtiff.": "libtiff", "libjpeg.": "libjpeg-turbo",
    "libfreetype.": "FreeType", "libcrypto.": "OpenSSL (libcrypto)", "libglfw.": "GLFW",
    "libOpenGL.": "libOpenGL", "libGLX.": "libOpenGL", "libGL.": "libOpenGL", "libstb.": "stb",
    "libEGL.": "libEGL", "libimgui.": "Dear ImGui",
    "libgtest": "GoogleTest", "libgmock": "GoogleMock", "libbenchmark": "Google Benchmark",
}
# The toolchain's C and C++ run-time: part of the system, not software ao carries.
SYSTEM = ("libc.so", "libm.so", "libstdc++.so", "libgcc_s.so", "ld-linux", "libdl.so", "libpthread.so", "librt.so")
# Compiled in: an #include of a header (its path's start) in ao's sources -> NOTICE's name.
HEADERS = {"CLI/": "CLI11", "nlohmann/": "nlohmann/json", "tiny_gltf.h": "tinygltf", "pybind11/": "pybind11",
           "imgui": "Dear ImGui", "EGL/": "libEGL", "hwy/": "Highway"}
# Packages the Python module imports (its .py files, and the binding's py::module_::import).
PACKAGES = {"numpy": "NumPy", "distributed": "Dask.distributed", "dask": "Dask"}


def sections():
    """NOTICE's sections: heading -> the names of its entries (each entry line's first column)."""
    out, heading = {}, None
    for line in (ROOT / "NOTICE").read_text().splitlines():
        if line and not line.startswith(" "):
            heading = line
            out[heading] = []
        elif heading and line.startswith("  ") and not line.startswith("   "):
            out[heading].append(re.split(r"\s{2,}", line.strip())[0])
    return {h: names for h, names in out.items() if names}


def where(name):
    """The kinds (LIBAO, CLI_ONLY, PYTHON, TESTS) of the sections whose entries name `name`."""
    kinds = set()
    for heading, names in sections().items():
        if any(name in n for n in names):
            kinds |= {k for k in (LIBAO, CLI_ONLY, PYTHON, TESTS) if heading.startswith(k)} or {heading}
    return kinds


def needed(path):
    """The sonames an ELF file names as NEEDED."""
    dump = subprocess.run(["objdump", "-p", str(path)], capture_output=True, text=True, check=True).stdout
    return re.findall(r"^\s+NEEDED\s+(\S+)", dump, re.M)


def notice_name(soname):
    if soname.startswith(SYSTEM):
        return None
    for start, name in SONAMES.items():
        if soname.startswith(start):
            return name
    pytest.fail(f"{soname} is linked but neither NOTICE nor this test's table knows it: add it to both")


def included(folders, start):
    pattern = re.compile(r'#include [<"]' + re.escape(start))
    return any(pattern.search(p.read_text(errors="replace")) for f in folders for p in (ROOT / f).rglob("*") if p.suffix in (".h", ".cpp"))


def test_the_sections_are_run_time_or_tests_only():
    for heading in sections():
        assert heading.startswith((LIBAO, CLI_ONLY, PYTHON, TESTS)), f"NOTICE: section '{heading}' is neither run time nor tests only"


def test_every_linked_library_is_named_where_it_is_used(ao_binary):
    module = set(filter(None, map(notice_name, needed(ao._ao.__file__))))
    command = set(filter(None, map(notice_name, needed(ao_binary))))
    assert "Embree 3" in module and "Highway" in command, "the NEEDED entries were not read"
    for name in module:
        assert where(name) & {LIBAO, PYTHON} and TESTS not in where(name), f"{name} (linked by the Python module): {where(name) or 'not in NOTICE'}"
    for name in command:
        assert where(name) & {LIBAO, CLI_ONLY} and TESTS not in where(name), f"{name} (linked by ao): {where(name) or 'not in NOTICE'}"
    for name in ("GoogleTest", "GoogleMock", "Google Benchmark"):
        assert name not in module | command, f"{name} is linked by what is installed"


def test_every_library_compiled_in_is_named():
    for start, name in HEADERS.items():
        folders = ["python/src"] if start == "pybind11/" else ["src/ao", "src/cli", "src/view"]
        if not included(folders, start):
            continue
        allowed = {PYTHON} if start == "pybind11/" else {LIBAO, CLI_ONLY}
        assert where(name) & allowed and TESTS not in where(name), f"{name} (#include <{start}...>): {where(name) or 'not in NOTICE'}"


def test_every_package_the_module_imports_is_named():
    sources = [p.read_text() for p in (ROOT / "python/ao").glob("*.py")] + [p.read_text() for p in (ROOT / "python/src").glob("*.cpp")]
    imported = set()
    for text in sources:
        imported |= set(re.findall(r"^\s*(?:import|from) (\w+)", text, re.M)) | set(re.findall(r'module_::import\("(\w+)"\)', text))
    assert "numpy" in imported and "distributed" in imported, "the imports were not read"
    for package in imported & PACKAGES.keys():
        name = PACKAGES[package]
        assert PYTHON in where(name) and TESTS not in where(name), f"{name} (import {package}): {where(name) or 'not in NOTICE'}"
