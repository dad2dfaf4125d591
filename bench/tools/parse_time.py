#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""How long a compiler takes to parse a translation unit that uses ao, against what no header of
ao can save: the standard library and nlohmann/json.hpp alone.

    bench/tools/parse_time.py [--cxx g++] [--runs 7] [-I DIR ...]

The include folders default to this tree's src/ and build/src/generated/ (ao/version.h); pass an
installed prefix's include/ to measure the installed headers, or an older tree's to compare. Each
round compiles, one after the other, with `CXX -std=c++20 -fsyntax-only` (parsing and template
instantiation, no code generation):
  render    examples/mesh_to_exr.cpp: a RenderRequest filled and run_render called, through
            ao/jobs/render.h alone
  umbrella  ao/ao.h, every installed header
  json      <nlohmann/json.hpp> alone
  std       the standard headers ao/jobs/render.h reads (its floor: <filesystem>, <string>, ...)
and prints each one's median wall and CPU seconds over the rounds (whole compiler processes, user
+ system of the child) and the load average before and after. On a shared machine compare
medians of one run only.
"""
import argparse
import os
import pathlib
import resource
import statistics
import subprocess
import tempfile
import time

EXAMPLES = pathlib.Path(__file__).resolve().parents[2] / "examples"
SOURCES = {
    "render": (EXAMPLES / "mesh_to_exr.cpp").read_text(),
    "umbrella": "#include <ao/ao.h>\nint main() { return 0; }\n",
    "json": "#include <nlohmann/json.hpp>\nint main() { return nlohmann::json::object().empty() ? 0 : 1; }\n",
    "std": "".join(f"#include <{h}>\n" for h in (
        "algorithm", "array", "atomic", "cmath", "cstdint", "filesystem", "functional", "map", "memory",
        "optional", "span", "string", "string_view", "typeindex", "unordered_map", "variant", "vector")) +
           "int main() { return 0; }\n",
}


def timed(cmd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.monotonic()
    subprocess.run(cmd, check=True)
    wall = time.monotonic() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(os.path.dirname(here))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cxx", default="g++")
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("-I", dest="includes", action="append",
                    default=None, help="include folder (default: src/ and build/src/generated/ of this tree)")
    args = ap.parse_args()
    includes = args.includes or [os.path.join(root, "src"), os.path.join(root, "build", "src", "generated")]
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    times = {name: [] for name in SOURCES}
    with tempfile.TemporaryDirectory() as tmp:
        for name, text in SOURCES.items():
            with open(os.path.join(tmp, name + ".cpp"), "w") as f:
                f.write(text)
        for _ in range(args.runs):
            for name in SOURCES:
                cmd = [args.cxx, "-std=c++20", "-fsyntax-only"] + [f"-I{d}" for d in includes] + [os.path.join(tmp, name + ".cpp")]
                times[name].append(timed(cmd))
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    print(f"{args.cxx} -std=c++20 -fsyntax-only, median of {args.runs} rounds")
    print(f"{'translation unit':<18}{'wall s':>8}{'cpu s':>8}")
    for name, runs in times.items():
        print(f"{name:<18}{statistics.median(w for w, _ in runs):>8.2f}{statistics.median(c for _, c in runs):>8.2f}")


if __name__ == "__main__":
    main()
