# SPDX-License-Identifier: Apache-2.0
# ao's Blender add-on against Cycles' AO bake in one Blender process, at equal error, each baker
# judged against its own converged map (BENCHMARKS.md, "bake", "In Blender"). Needs Debian's blender
# and ao's Python package on PYTHONPATH (build/python):
#   PYTHONPATH=build/python blender -b --factory-startup --python bench/blender/addon_vs_cycles.py -- \
#       MESH.obj SIZE OUT_DIR [--ao RAYS:FILTER ...] [--spp SAMPLES ...] [--rounds N] [--reference N]
# The mesh is baked into its own UVs on 2 threads by both: ao through bpy.ops.object.ao_bake (the
# add-on registered from the package), Cycles through bpy.ops.object.bake(type="AO") (unlimited
# distance, no denoising or adaptive sampling, margin 0). References: the add-on at N rays per texel
# unfiltered with another seed, Cycles at N samples; kept in OUT_DIR and reused. Each round bakes
# every setting once, the bakers alternated; a bake's cost is the process's CPU seconds over the
# operator call (time.process_time: every thread of the process, the add-on's mesh conversion and
# Cycles' BVH build included) and its wall seconds. Errors: RMSE over the texels both references
# cover. Refuses to start above load average 2 (ALLOW_LOAD=1 runs it and marks it); prints the load
# average before and after, a markdown table of medians, and for each Cycles setting the cheapest ao
# setting at its error with the ratio of CPU seconds (compare_summary.verdict).
import os
import statistics
import sys
import time

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare_summary  # noqa: E402
from mesh_io import bake_image, load_mesh  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:]
mesh_path, size, out_dir = args[0], int(args[1]), args[2]
opts = {"--ao": [], "--spp": [], "--rounds": ["1"], "--reference": ["1024"]}
key = None
for a in args[3:]:
    if a in opts:
        key = a
        if a in ("--rounds", "--reference"):
            opts[a] = []
    else:
        opts[key].append(a)
ao_settings = opts["--ao"] or ["16:1", "24:1", "64:1", "64:0"]
cycles_settings = [int(s) for s in (opts["--spp"] or ["64"])]
rounds, reference = int(opts["--rounds"][0]), int(opts["--reference"][0])
os.makedirs(out_dir, exist_ok=True)

import ao  # noqa: E402
import ao._blender_addon as addon  # noqa: E402

bpy.ops.wm.read_factory_settings(use_empty=True)
addon.register()
ao.set_threads(2)
scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.use_denoising = False
scene.cycles.use_adaptive_sampling = False
scene.render.threads_mode = "FIXED"
scene.render.threads = 2
world = bpy.data.worlds.new("World")
scene.world = world
world.light_settings.distance = 1e6  # unlimited, as ao bake without --max-distance

obj, _ = load_mesh(mesh_path, "mesh")
bpy.context.view_layer.objects.active = obj
obj.select_set(True)
image = bake_image(obj, "cycles", size)


def pixels(img):
    w, h = img.size
    data = np.empty(w * h * 4, np.float32)
    img.pixels.foreach_get(data)
    return data.reshape(h, w, 4)[..., 0].copy()


def timed(call):
    cpu, wall = time.process_time(), time.perf_counter()
    call()
    return time.process_time() - cpu, time.perf_counter() - wall


def bake_cycles(samples):
    scene.cycles.samples = samples
    image.pixels.foreach_set(np.zeros(size * size * 4, np.float32))
    cpu, wall = timed(lambda: bpy.ops.object.bake(type="AO", margin=0, use_clear=False))
    return pixels(image), cpu, wall


def bake_ao(rays, sigma, seed=1):
    cpu, wall = timed(lambda: bpy.ops.object.ao_bake(size=size, samples=rays, denoise=sigma, padding=0, seed=seed))
    img = bpy.data.images["mesh_ao"]
    return pixels(img), cpu, wall


def cached(name, make):
    path = os.path.join(out_dir, name + ".npy")
    if os.path.exists(path):
        return np.load(path)
    m = make()[0]
    np.save(path, m)
    return m


refusal = compare_summary.load_refusal()
if refusal:
    sys.exit("addon_vs_cycles.py: " + refusal)
print("load average before:", " ".join("%.2f" % x for x in os.getloadavg()),
      "(ALLOW_LOAD: CPU seconds not comparable above %g)" % compare_summary.LOAD_LIMIT if os.environ.get("ALLOW_LOAD") else "", flush=True)
ref_ao = cached(f"ao-reference-{reference}", lambda: bake_ao(reference, 0.0, seed=99))
ref_cy = cached(f"cycles-reference-{reference}", lambda: bake_cycles(reference))
mask = (ref_ao > 0) & (ref_cy > 0)
rows = {}
for _ in range(rounds):
    for s in ao_settings:
        rays, sigma = s.split(":")
        m, cpu, wall = bake_ao(int(rays), float(sigma))
        rows.setdefault(("ao", f"{rays} rays/texel, filter {sigma}"), []).append((float(np.sqrt(np.mean((m - ref_ao)[mask] ** 2))), cpu, wall))
    for spp in cycles_settings:
        m, cpu, wall = bake_cycles(spp)
        rows.setdefault(("Cycles", f"{spp} samples"), []).append((float(np.sqrt(np.mean((m - ref_cy)[mask] ** 2))), cpu, wall))
print("load average after: ", " ".join("%.2f" % x for x in os.getloadavg()))
print(f"texels compared: {int(mask.sum())}; converged maps (ao {reference} rays unfiltered, Cycles {reference} samples) differ by RMSE "
      f"{float(np.sqrt(np.mean((ref_ao - ref_cy)[mask] ** 2))):.4f}")
print("| baker | setting | RMSE vs its own converged map | CPU s (median) | wall s (median) | rounds |")
print("|---|---|---:|---:|---:|---:|")
for (baker, setting), runs in rows.items():
    print(f"| {baker} | {setting} | {statistics.median(r[0] for r in runs):.5f} | {statistics.median(r[1] for r in runs):.2f} | "
          f"{statistics.median(r[2] for r in runs):.2f} | {len(runs)} |")
print()
print("\n".join(compare_summary.verdict({(baker, setting): {"own": statistics.median(r[0] for r in runs), "cpu": statistics.median(r[1] for r in runs)}
                                         for (baker, setting), runs in rows.items()})))
