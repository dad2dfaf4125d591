#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Rays per second of `ao bake` against `ao render` on the same mesh and threads, in one alternated run.

    bench/tools/bake_ray_rate.py MESH [--ao build/src/ao] [--baseline OLD_AO] [--pairs 5] [--threads 2]
                                 [--size 1024] [--samples 24] [--spp 64] [--render-radius R]

Each round runs, one after the other, `ao bake MESH -s SIZE --samples SAMPLES --denoise 0 --json`
(with --baseline: the same with OLD_AO too) and `ao render MESH --spp SPP --json`, so every round's
commands see the same machine load. The bake's rate is its ray count over its bake call
(stats.rays / timings.bake_ms: the texels' rays, without loading, coverage, BVH and writing); the
render's is its own rays_per_second (rays over the AO pass). The render's rays stop at its radius
(0.1 of the mesh's diagonal by default) and the bake's do not: --render-radius 1e6 gives the render
rays as long as the bake's, the comparison at equal ray length. Reported: the median of each rate,
the median and range of the per-round ratios bake / render (and new bake / baseline bake), and
the bake call's parts (UV coverage against the bake call, medians). The load average is printed
before and after: on a shared machine only the ratios within one run mean anything.
"""
import argparse
import json
import os
import statistics
import subprocess
import tempfile


def run_json(args):
    return json.loads(subprocess.run(args, check=True, capture_output=True, text=True).stdout)


def bake(ao, mesh, opts, out):
    d = run_json([ao, "--threads", str(opts.threads), "-q", "bake", mesh, "-s", str(opts.size), "--samples", str(opts.samples),
                  "--denoise", "0", "--padding", "0", "-o", out, "--json"])
    t = d["timings"]
    return {"rate": d["stats"]["rays"] / (t["bake_ms"] / 1000.0), "bake_ms": t["bake_ms"], "uv_coverage_ms": t["uv_coverage_ms"]}


def render(ao, mesh, opts, out):
    radius = ["-R", str(opts.render_radius)] if opts.render_radius else []
    d = run_json([ao, "--threads", str(opts.threads), "-q", "render", mesh, "--spp", str(opts.spp), *radius, "-o", out, "--json"])
    return {"rate": d["rays_per_second"]}


def summary(name, values):
    return "%s: median %.4g (%.4g - %.4g)" % (name, statistics.median(values), min(values), max(values))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("mesh")
    p.add_argument("--ao", default="build/src/ao")
    p.add_argument("--baseline", help="a second ao binary whose bake runs in each round too")
    p.add_argument("--pairs", type=int, default=5)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--size", type=int, default=1024)
    p.add_argument("--samples", type=int, default=24)
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--render-radius", type=float, help="the render's -R (default: its own, 0.1 of the diagonal)")
    opts = p.parse_args()
    print("load average before:", " ".join("%.2f" % x for x in os.getloadavg()))
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        bake_out, render_out = os.path.join(tmp, "bake.exr"), os.path.join(tmp, "render.png")
        for _ in range(opts.pairs):
            row = {"bake": bake(opts.ao, opts.mesh, opts, bake_out), "render": render(opts.ao, opts.mesh, opts, render_out)}
            if opts.baseline:
                row["baseline"] = bake(opts.baseline, opts.mesh, opts, bake_out)
            rows.append(row)
    print("load average after: ", " ".join("%.2f" % x for x in os.getloadavg()))
    print(summary("bake rays/s (M)", [r["bake"]["rate"] / 1e6 for r in rows]))
    print(summary("render rays/s (M)", [r["render"]["rate"] / 1e6 for r in rows]))
    print(summary("bake / render rays/s", [r["bake"]["rate"] / r["render"]["rate"] for r in rows]))
    print(summary("bake call, ms", [r["bake"]["bake_ms"] for r in rows]))
    print(summary("uv coverage, ms", [r["bake"]["uv_coverage_ms"] for r in rows]))
    print(summary("uv coverage / bake call", [r["bake"]["uv_coverage_ms"] / r["bake"]["bake_ms"] for r in rows]))
    if opts.baseline:
        print(summary("baseline bake rays/s (M)", [r["baseline"]["rate"] / 1e6 for r in rows]))
        print(summary("baseline bake / render rays/s", [r["baseline"]["rate"] / r["render"]["rate"] for r in rows]))
        print(summary("bake rays/s, new / baseline", [r["bake"]["rate"] / r["baseline"]["rate"] for r in rows]))
        print(summary("baseline uv coverage, ms", [r["baseline"]["uv_coverage_ms"] for r in rows]))
        print(summary("uv coverage, new / baseline", [r["bake"]["uv_coverage_ms"] / r["baseline"]["uv_coverage_ms"] for r in rows]))


if __name__ == "__main__":
    main()
