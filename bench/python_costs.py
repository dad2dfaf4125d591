# SPDX-License-Identifier: Apache-2.0
"""What the Python module and ao.batch cost (BENCHMARKS.md "Python and Dask", docs/cluster.md):

  render   a 1280 x 720 render through ao.render against the same job's own time inside the library
           (the sum of its summary's timings: load, BVH, G-buffer, method, write; the few checks
           between them are not timed, so the ratio overstates the binding's share), median of 7
  tasks    the Dask scheduler's cost per task: 10,000 no-op tasks on a local cluster of 2 workers
           of one thread each (tcp on 127.0.0.1), wall time / 10,000
  batch    python3 -m ao.batch bake on 20 tiny meshes with one worker and with two workers of one
           thread each: wall time, the tasks' own time, and the overhead per task

    PYTHONPATH=build/python /usr/bin/python3 bench/python_costs.py [render|tasks|batch ...]
"""

import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import ao


def bench_render(repeats=7):
    cam = ao.Camera(width=1280, height=720)
    ratios, walls = [], []
    for method, kwargs in (("volumetric", {}), ("raytraced", {"spp": 16})):
        ao.render("default", cam, method, **kwargs)  # warm: page cache, Embree, TBB threads
        for _ in range(repeats):
            t = time.perf_counter()
            out = ao.render("default", cam, method, full=True, **kwargs)
            wall = (time.perf_counter() - t) * 1000
            job = sum(out["summary"]["timings"].values())
            ratios.append(wall / job)
            walls.append((method, wall, job))
        print(f"render {method} 1280x720: ao.render {statistics.median(w for m, w, j in walls if m == method):.1f} ms, "
              f"the job {statistics.median(j for m, w, j in walls if m == method):.1f} ms, "
              f"ratio median {statistics.median(ratios[-repeats:]):.4f}, max {max(ratios[-repeats:]):.4f}")


def noop(x):
    return x


def bench_tasks(count=10000):
    from distributed import Client, LocalCluster
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None) as cluster, \
            Client(cluster) as client:
        client.gather(client.map(noop, range(100), pure=False))  # warm
        t = time.perf_counter()
        client.gather(client.map(noop, range(count), pure=False))
        wall = time.perf_counter() - t
    print(f"tasks: {count} no-op tasks on 2 local workers: {wall:.2f} s, {wall / count * 1e6:.0f} us per task, "
          f"{count / wall:.0f} tasks/s")


def write_grid(path, n, seed):
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    x, z = i / n, j / n
    y = 0.35 * np.exp(-((x - 0.5) ** 2 + (z - 0.5) ** 2) / 0.02) + 0.05 * seed * x
    with open(path, "w") as f:
        for a, b, c in zip(x.ravel(), y.ravel(), z.ravel()):
            f.write(f"v {a:.9g} {b:.9g} {c:.9g}\nvt {a:.9g} {c:.9g}\n")
        for a in range(n):
            for b in range(n):
                v00, v10, v01, v11 = a * (n + 1) + b + 1, (a + 1) * (n + 1) + b + 1, a * (n + 1) + b + 2, (a + 1) * (n + 1) + b + 2
                f.write(f"f {v00}/{v00} {v01}/{v01} {v11}/{v11}\nf {v00}/{v00} {v11}/{v11} {v10}/{v10}\n")


def bench_batch(meshes=20, size=256, samples=64):
    with tempfile.TemporaryDirectory(prefix="ao-bench-") as tmp:
        folder = os.path.join(tmp, "meshes")
        os.mkdir(folder)
        for k in range(meshes):
            write_grid(os.path.join(folder, f"grid{k:02d}.obj"), 24, k)
        for workers in (1, 2):
            out = os.path.join(tmp, f"out{workers}")
            cmd = [sys.executable, "-m", "ao.batch", "bake", folder, "--out-dir", out, "--local", str(workers), "--threads", "1",
                   "--size", str(size), "-p", f"samples={samples}"]
            t = time.perf_counter()
            p = subprocess.run(cmd, capture_output=True, text=True, check=True)
            wall = time.perf_counter() - t
            task_s = sum(float(line.rsplit("(", 1)[1].split()[0]) for line in p.stdout.splitlines() if line.startswith("["))
            print(f"batch: {meshes} meshes {size}x{size} {samples} rays/texel, {workers} worker(s) of 1 thread: {wall:.2f} s wall "
                  f"(cluster start included), tasks {task_s:.2f} s, overhead per task {(wall * workers - task_s) / meshes * 1000:.0f} ms")
            t = time.perf_counter()
            subprocess.run(cmd, capture_output=True, text=True, check=True)
            print(f"batch: rerun with every output present (nothing submitted): {time.perf_counter() - t:.2f} s")


if __name__ == "__main__":
    which = sys.argv[1:] or ["render", "tasks", "batch"]
    for name in which:
        {"render": bench_render, "tasks": bench_tasks, "batch": bench_batch}[name]()
