# SPDX-License-Identifier: Apache-2.0
# Errors of a bake of the box on a floor (bench/tools/box_on_floor_obj.py) against a reference bake,
# over the whole map and over the contact texels of each side, as tests/bake/bake_test.cpp's
# box_on_floor() marks them: the floor's texels whose centre lies within 1.5 floor texels of the
# cube's footprint outline (inside or outside it), and the four sides' texels whose centre lies within
# 1.5 texels of the floor. The floor side is where a filter softens the contact shadow (V climbs from
# about 0.5 to 0.9 across a few texels of the chart); the test pools both sides.
#   blender -b --factory-startup --python bench/blender/box_contacts.py -- MAP.exr REFERENCE.exr
# Prints "whole R texels N floor_contact F texels NF side_contact S texels NS". Texels: those whose
# square overlaps a chart with positive area (what ao bake covers), read with Blender's image loader.
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mesh_io import read_pixels  # noqa: E402

SIDE, MARGIN = 1 / 3, 0.01    # the OBJ's 3 x 3 grid of charts and their margin, in UV
LO, HI = -0.5, 0.5            # the cube's footprint, world x and z


def masks(n):
    """covered, floor_contact, side_contact for an n x n map, rows from the bottom (v increasing)."""
    centre = (np.arange(n) + 0.5) / n
    u, v = np.meshgrid(centre, centre)              # [row, column]: v by row, u by column
    cx, cy = np.floor(u / SIDE).astype(int), np.floor(v / SIDE).astype(int)
    span = SIDE - 2 * MARGIN
    a, c = (u - cx * SIDE - MARGIN) / span, (v - cy * SIDE - MARGIN) / span  # position within the chart
    inside = (a >= 0) & (a <= 1) & (c >= 0) & (c <= 1)
    chart_texels = span * n
    # The floor chart (0, 0): world x = -2 + 4a, z = 2 - 4c; a floor texel is 4 / chart_texels wide.
    px, pz = np.abs(-2 + 4 * a), np.abs(2 - 4 * c)
    outside = np.hypot(np.maximum(px - HI, 0), np.maximum(pz - HI, 0))
    distance = np.where(outside > 0, outside, HI - np.maximum(px, pz))
    floor = inside & (cx == 0) & (cy == 0) & (distance <= 1.5 * 4 / chart_texels)
    # The sides: cells (2, 0), (0, 1), (1, 1), (2, 1); height c, a texel 1 / chart_texels high.
    is_side = ((cx == 2) & (cy == 0)) | ((cy == 1) & (cx <= 2))
    side = inside & is_side & (c <= 1.5 / chart_texels)
    # Covered: the texel's square overlaps a chart's rectangle with positive area.
    lo_edge, hi_edge = np.arange(n) / n, (np.arange(n) + 1) / n
    covered = np.zeros((n, n), bool)
    for ccx in range(3):
        for ccy in range(2):
            cols = (lo_edge < ccx * SIDE + SIDE - MARGIN) & (hi_edge > ccx * SIDE + MARGIN)
            rows = (lo_edge < ccy * SIDE + SIDE - MARGIN) & (hi_edge > ccy * SIDE + MARGIN)
            covered |= rows[:, None] & cols[None, :]
    return covered, floor & covered, side & covered


def rmse(a, b, mask):
    d = a[mask].astype(np.float64) - b[mask]
    return np.sqrt(np.mean(d * d)), int(mask.sum())


args = sys.argv[sys.argv.index("--") + 1:]
m, ref = read_pixels(args[0])[..., 0], read_pixels(args[1])[..., 0]
if m.shape != ref.shape or m.shape[0] != m.shape[1]:
    sys.exit("box_contacts.py: the map and the reference must be the same square size")
covered, floor, side = masks(m.shape[0])
parts = [("whole", covered), ("floor_contact", floor), ("side_contact", side)]
print(" ".join("%s %.5f texels %d" % ((name,) + rmse(m, ref, mask)) for name, mask in parts))
