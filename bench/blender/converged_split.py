# SPDX-License-Identifier: Apache-2.0
# Where ao's and Cycles' converged maps differ (docs/methods/bake.md, "Against Cycles' converged
# map"): two ao maps per texel sampling (area, centre; other seeds) and two Cycles maps (other
# seeds), all unfiltered and unpadded, compared over the texels every map covers. Each pair's RMS
# is split into noise (each map's own, from the RMS between its two seeds: noise^2 = RMS^2 / 2) and
# what lies beyond it, overall and by kind of texel: those whose centre lies in two or more UV
# triangles (the mesh's charts overlap there), chart-border texels (an uncovered 4-neighbour), and
# the rest. Run by bench/blender/converged_split.sh; by hand:
#   blender -b --factory-startup --python bench/blender/converged_split.py -- MESH.obj DIR
# with DIR holding ao-area-{99,7}.exr, ao-centre-{99,7}.exr, cyc-{0,1}.exr.
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mesh_io import read_pixels  # noqa: E402

mesh, folder = sys.argv[sys.argv.index("--") + 1:][:2]


def pixels(path):
    return read_pixels(path)[::-1, :, 0].astype(np.float64)  # rows from the top, as ao writes them


def overlapping_centres(path, w, h):
    """Texel centres inside two or more UV triangles of the OBJ (texel rows from the top, v = 1)."""
    vt, faces = [], []
    for line in open(path):
        if line.startswith("vt "):
            vt.append([float(x) for x in line.split()[1:3]])
        elif line.startswith("f "):
            idx = [int(p.split("/")[1]) - 1 for p in line.split()[1:]]
            faces += [(idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1)]
    vt = np.array(vt) * [w, -h] + [0, h]
    count = np.zeros((h, w), np.int32)
    for f in faces:
        (ax, ay), (bx, by), (cx, cy) = vt[list(f)]
        det = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay)
        if det == 0:
            continue
        x0, x1 = max(int(np.floor(min(ax, bx, cx) - 0.5)), 0), min(int(np.ceil(max(ax, bx, cx) - 0.5)), w - 1)
        y0, y1 = max(int(np.floor(min(ay, by, cy) - 0.5)), 0), min(int(np.ceil(max(ay, by, cy) - 0.5)), h - 1)
        xs, ys = np.meshgrid(np.arange(x0, x1 + 1), np.arange(y0, y1 + 1))
        px, py = xs + 0.5, ys + 0.5
        l1 = ((px - ax) * (cy - ay) - (cx - ax) * (py - ay)) / det
        l2 = ((bx - ax) * (py - ay) - (px - ax) * (by - ay)) / det
        inside = (l1 > 1e-6) & (l2 > 1e-6) & (l1 + l2 < 1 - 1e-6)
        count[ys[inside], xs[inside]] += 1
    return count >= 2


names = ["ao-area-99", "ao-area-7", "ao-centre-99", "ao-centre-7", "cyc-0", "cyc-1"]
m = {n: pixels(f"{folder}/{n}.exr") for n in names}
h, w = m["cyc-0"].shape
every = np.logical_and.reduce([v > 1e-6 for v in m.values()])
covered = m["cyc-0"] > 0
inner = every.copy()
for dy, dx in [(-1, 0), (1, 0), (0, -1), (0, 1)]:
    inner &= np.roll(np.roll(covered, dy, 0), dx, 1)
over = overlapping_centres(mesh, w, h)
noise = {}
for a, b in [("ao-area-99", "ao-area-7"), ("ao-centre-99", "ao-centre-7"), ("cyc-0", "cyc-1")]:
    d = (m[a] - m[b])[every]
    noise[a] = noise[b] = float(np.mean(d * d)) / 2
    print(f"noise of one {a.rsplit('-', 1)[0]} map: {np.sqrt(noise[a]):.5f}")
print(f"texels every map covers: {int(every.sum())}")
for label, sel in [("all", every), ("overlapping UV charts", every & over), ("chart border", every & ~inner & ~over),
                   ("interior", every & inner & ~over), ("all but overlapping charts", every & ~over)]:
    for a, b in [("ao-area-99", "cyc-0"), ("ao-centre-99", "cyc-0")]:
        d = (m[a] - m[b])[sel]
        s = float(np.mean(d * d))
        print(f"{label:27s} {int(sel.sum()):6d} texels  {a[:-3]:9s} - cycles: rms {np.sqrt(s):.5f}  beyond noise {np.sqrt(max(s - noise[a] - noise[b], 0)):.5f}"
              f"  share of the squares beyond noise {(s - noise[a] - noise[b]) * sel.sum():.3g}")
