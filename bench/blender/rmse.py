# SPDX-License-Identifier: Apache-2.0
# RMSE of a baked AO map against a reference map over the texels both cover, read with Blender's
# image loader (both files go through the same one, so row order cannot differ between them).
#   blender -b --factory-startup --python bench/blender/rmse.py -- MAP.exr REFERENCE.exr [--flip]
# The texels compared are those both maps cover: `ao bake --padding 0` writes 0 outside the charts,
# and Cycles (margin 0) leaves its black background where no texel centre falls inside a triangle
# (ao also covers texels a chart only partly overlaps, with the area-weighted mean). A covered texel
# with V below 1e-6 would be left out too; there are none in practice.
# --flip compares MAP upside down (a check of the UV convention). Prints "rmse R texels N mean_signed S se E":
# S the mean of MAP minus the mean of REFERENCE over those texels, E = R / sqrt(N) the standard error
# of MAP's mean were its texels' errors independent (a filtered map's errors are correlated over a
# few texels, which makes its true standard error a few times larger).
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mesh_io import read_pixels  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:]
flip = "--flip" in args
paths = [a for a in args if a != "--flip"]

a, b = read_pixels(paths[0]), read_pixels(paths[1])
if flip:
    a = a[::-1]
mask = (a[..., 0] > 1e-6) & (b[..., 0] > 0)
diff = a[..., 0][mask] - b[..., 0][mask]
rmse = np.sqrt(np.mean(diff * diff))
print(f"rmse {rmse:.5f} texels {int(mask.sum())} mean_signed {diff.mean():+.6f} se {rmse / np.sqrt(mask.sum()):.6f}")
