#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
# Writes an OBJ of a unit cube standing on a 4 x 4 floor, each of the six faces (floor, cube top and
# four sides) its own UV chart in a 3 x 3 grid: a hard-surface bake case with contact-shadow edges on
# flat charts (docs/methods/bake.md, "Denoising").
#   bench/tools/box_on_floor_obj.py OUT.obj
import sys

positions, uvs, faces = [], [], []


def quad(corners, cell):
    cx, cy = cell
    margin, side = 0.01, 1 / 3
    chart = [(cx * side + margin, cy * side + margin), (cx * side + side - margin, cy * side + margin),
             (cx * side + side - margin, cy * side + side - margin), (cx * side + margin, cy * side + side - margin)]
    base = len(positions)
    positions.extend(corners)
    uvs.extend(chart)
    faces.extend([(base, base + 1, base + 2), (base, base + 2, base + 3)])


lo, hi, top = -0.5, 0.5, 1.0
quad([(-2, 0, 2), (2, 0, 2), (2, 0, -2), (-2, 0, -2)], (0, 0))      # floor, facing up
quad([(lo, top, hi), (hi, top, hi), (hi, top, lo), (lo, top, lo)], (1, 0))  # cube top
quad([(lo, 0, hi), (hi, 0, hi), (hi, top, hi), (lo, top, hi)], (2, 0))      # +z side
quad([(hi, 0, lo), (lo, 0, lo), (lo, top, lo), (hi, top, lo)], (0, 1))      # -z side
quad([(hi, 0, hi), (hi, 0, lo), (hi, top, lo), (hi, top, hi)], (1, 1))      # +x side
quad([(lo, 0, lo), (lo, 0, hi), (lo, top, hi), (lo, top, lo)], (2, 1))      # -x side
with open(sys.argv[1], "w") as f:
    f.writelines("v %g %g %g\n" % p for p in positions)
    f.writelines("vt %g %g\n" % t for t in uvs)
    f.writelines("f %d/%d %d/%d %d/%d\n" % (a + 1, a + 1, b + 1, b + 1, c + 1, c + 1) for a, b, c in faces)
