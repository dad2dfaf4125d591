# SPDX-License-Identifier: Apache-2.0
# Blender (Cycles) AO bake of one OBJ into its UVs: the peer baker `ao bake` is compared with.
# Run by bench/blender/compare.sh; by hand:
#   blender -b --factory-startup --python bench/blender/bake_ao.py -- MESH.obj SIZE SAMPLES OUT.exr THREADS [HIGH.obj|HIGH.off CAGE_EXTRUSION]
# With HIGH: high to low, Cycles' "selected to active" (the AO of HIGH, found by rays from MESH
# pushed out by CAGE_EXTRUSION along its normals, in MESH's UVs); MESH itself is invisible to the
# AO rays, as the low mesh is to `ao bake --high`.
# CYCLES_SEED=N in the environment sets Cycles' seed (default 0). Writes OUT.exr (linear float
# RGB, AO in every channel) and
# prints one line "bake_seconds S" (the bpy.ops.object.bake call alone: BVH build and baking).
import os
import sys
import time

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mesh_io import bake_image, load_mesh  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:]
mesh_path, size, samples, out_path, threads = args[0], int(args[1]), int(args[2]), args[3], int(args[4])
high_path, cage_extrusion = (args[5], float(args[6])) if len(args) > 6 else (None, 0.0)

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = samples
scene.cycles.use_denoising = False
scene.cycles.use_adaptive_sampling = False
scene.cycles.seed = int(os.environ.get("CYCLES_SEED", "0"))  # another seed: an independent map, for Cycles' own noise
scene.render.threads_mode = "FIXED"
scene.render.threads = threads

# The OBJ as written (no axis change matters for AO; keep the file's coordinates).
obj, _ = load_mesh(mesh_path, "low")
high = None
if high_path:
    high, _ = load_mesh(high_path, "high")
    high.select_set(True)
    for what in ("camera", "diffuse", "glossy", "transmission", "volume_scatter", "shadow"):
        setattr(obj, "visible_" + what, False)
bpy.context.view_layer.objects.active = obj
obj.select_set(True)

# Unlimited AO distance, as `ao bake` without --max-distance: Cycles' AO bake reads the world's.
world = bpy.data.worlds.new("World")
scene.world = world
world.light_settings.distance = 1e6

image = bake_image(obj, "ao", size)

bake = scene.render.bake
bake.margin = 0
bake.use_clear = False
start = time.perf_counter()
if high:
    bpy.ops.object.bake(type="AO", margin=0, use_clear=False, use_selected_to_active=True, cage_extrusion=cage_extrusion)
else:
    bpy.ops.object.bake(type="AO", margin=0, use_clear=False)
print(f"bake_seconds {time.perf_counter() - start:.3f}")

image.filepath_raw = out_path
image.file_format = "OPEN_EXR"
image.save()
