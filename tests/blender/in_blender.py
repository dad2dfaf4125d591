# SPDX-License-Identifier: Apache-2.0
"""Runs inside Blender (`blender -b --python in_blender.py -- OUT_DIR`) for test_addon.py: with the
add-on enabled from the user preferences (as `python3 -m ao.blender install` leaves it), it makes
the test scenes from Blender's own primitives, bakes them with bpy.ops.object.ao_bake, and writes
into OUT_DIR what the test compares with `ao bake`:

- <case>.npy: the image the operator left (Blender's RGBA float pixels, rows from the bottom);
- the meshes as OBJ files, written corner by corner from Blender's loop triangles by the plain
  loop below (positions, loop normals and UVs printed with 9 significant digits, which float32
  values survive), not by the add-on's numpy path;
- results.json: what each call returned or raised;
- scene.blend: the scene, for in_window.py.
"""

import json
import os
import sys
import threading
import time

import bpy
import numpy as np

OUT = sys.argv[sys.argv.index("--") + 1]
SIZE, SAMPLES = 128, 16
results = {"addon_enabled": "ao_bake" in bpy.context.preferences.addons}


def write_obj(path, obj, uvs=True, cage=None):
    """`obj`'s evaluated mesh, one v/vt/vn per corner of each loop triangle (world = object space:
    the test objects are not transformed). With `cage`: the cage object's positions at the same
    vertices, the normals and UVs of `obj` (the cage's topology is `obj`'s)."""
    assert obj.matrix_world == obj.matrix_world.Identity(4)
    mesh = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
    mesh.calc_loop_triangles()
    mesh.calc_normals_split()
    co = [v.co.copy() for v in (cage.data.vertices if cage else mesh.vertices)]
    layer = mesh.uv_layers.active.data if uvs else None
    lines, faces = [], []
    for t in mesh.loop_triangles:
        corners = []
        for li in t.loops:
            loop = mesh.loops[li]
            lines.append("v %.9g %.9g %.9g" % tuple(co[loop.vertex_index]))
            lines.append("vn %.9g %.9g %.9g" % tuple(loop.normal))
            if uvs:
                lines.append("vt %.9g %.9g" % tuple(layer[li].uv))
            k = len(faces) * 3 + len(corners) + 1
            corners.append(f"{k}/{k}/{k}" if uvs else f"{k}//{k}")
        faces.append("f " + " ".join(corners))
    obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh_clear()
    with open(path, "w") as f:
        f.write("\n".join(lines + faces) + "\n")


def monkey(name, subdivisions=0):
    bpy.ops.mesh.primitive_monkey_add(location=(0, 0, 0))
    obj = bpy.context.active_object
    obj.name = name
    bpy.ops.object.shade_smooth()
    if subdivisions:
        obj.modifiers.new("subdivision", "SUBSURF").levels = subdivisions
    return obj


def select(active, *others):
    bpy.ops.object.select_all(action="DESELECT")
    for o in (active,) + others:
        o.select_set(True)
    bpy.context.view_layer.objects.active = active


def bake(case, **options):
    """The operator's result and the image it left (or its error), recorded under `case`; the AO
    family's images as <case>_bent, <case>_thickness, <case>_cavity."""
    base = bpy.context.active_object.name
    try:
        results[case] = {"returned": sorted(bpy.ops.object.ao_bake(**options))}
    except RuntimeError as e:  # an operator's {'ERROR'} report
        results[case] = {"error": str(e)}
    for kind in ("bent", "thickness", "cavity"):
        image = bpy.data.images.get(base + "_" + kind)
        if image is not None:
            w, h = image.size
            pixels = np.empty(w * h * 4, np.float32)
            image.pixels.foreach_get(pixels)
            np.save(os.path.join(OUT, f"{case}_{kind}.npy"), pixels.reshape(h, w, 4))
            bpy.data.images.remove(image)
    name = base + "_ao"
    image = bpy.data.images.get(name)
    results[case]["image"] = image is not None
    if image is not None:
        w, h = image.size
        results[case].update(width=w, height=h, float=image.is_float, colorspace=image.colorspace_settings.name)
        pixels = np.empty(w * h * 4, np.float32)
        image.pixels.foreach_get(pixels)
        np.save(os.path.join(OUT, case + ".npy"), pixels.reshape(h, w, 4))
        image.filepath_raw = os.path.join(OUT, case + ".png")
        image.file_format = "PNG"
        image.save()
        bpy.data.images.remove(image)


bpy.ops.object.select_all(action="SELECT")
bpy.ops.object.delete()

# One mesh: the defaults, then every option set.
low = monkey("Suzanne")
write_obj(os.path.join(OUT, "low.obj"), low)
select(low)
bake("single", size=SIZE, samples=SAMPLES)
bake("options", size=SIZE, samples=SAMPLES, max_distance=0.5, membership="linear", denoise=0.0, padding=3, seed=7, ignore_back_faces=True)
# The AO family: bent normals in tangent space, thickness, cavity, with a narrower cone.
bake("family", size=SIZE, samples=SAMPLES, spread_angle=150.0, bent_normals=True, thickness=True, thickness_distance=0.3, cavity=True,
     cavity_distance=0.05)

# Tangent frames: Suzanne triangulated (so that Blender's MikkTSpace and ao see the same
# triangles), the UVs of her left half mirrored (u -> 1 - u) so that both orientations occur,
# Blender's calc_tangents() per corner of each loop triangle, in the order write_obj writes them.
tri = monkey("Tri")
tri.modifiers.new("triangulate", "TRIANGULATE")
select(tri)
bpy.ops.object.modifier_apply(modifier="triangulate")
uv = tri.data.uv_layers.active.data
for poly in tri.data.polygons:
    if poly.center.x < 0:
        for li in poly.loop_indices:
            uv[li].uv.x = 1.0 - uv[li].uv.x
write_obj(os.path.join(OUT, "tri.obj"), tri)
tri_mesh = tri.data
tri_mesh.calc_loop_triangles()
tri_mesh.calc_tangents()
frames = [list(tri_mesh.loops[li].tangent) + [tri_mesh.loops[li].bitangent_sign] for t in tri_mesh.loop_triangles for li in t.loops]
np.save(os.path.join(OUT, "tri_tangents.npy"), np.array(frames, np.float32))
bpy.data.objects.remove(tri)

# High to low: a subdivided copy into the plain one's UVs, rays from the pushed-out low mesh, then
# from a cage object (the low mesh with its vertices moved out along their normals).
high = monkey("High", subdivisions=2)
write_obj(os.path.join(OUT, "high.obj"), high, uvs=False)
select(low, high)
bake("high", size=SIZE, samples=SAMPLES, selected_to_active=True, cage_extrusion=0.02)
cage = low.copy()
cage.data = low.data.copy()
cage.name = "Cage"
bpy.context.collection.objects.link(cage)
for v in cage.data.vertices:
    v.co += 0.03 * v.normal
write_obj(os.path.join(OUT, "cage.obj"), low, cage=cage)
select(low, high)
bake("cage", size=SIZE, samples=SAMPLES, selected_to_active=True, cage_object="Cage", max_back=0.05)

# Bad input: no UV map; a cage of another topology.
bpy.ops.mesh.primitive_cube_add()
cube = bpy.context.active_object
cube.name = "NoUV"
cube.data.uv_layers.remove(cube.data.uv_layers[0])
bake("no_uv", size=SIZE, samples=SAMPLES)
select(low, high)
bake("bad_cage", size=SIZE, samples=SAMPLES, selected_to_active=True, cage_object="High")

# Cancel: a bake that would take minutes, cancelled after half a second as Esc cancels it.
import ao._blender_addon as addon  # noqa: E402  (the module the add-on runs)
select(low)
threading.Timer(0.5, addon.cancel).start()
start = time.monotonic()
bake("cancel", size=1024, samples=4096)
results["cancel"]["seconds"] = time.monotonic() - start

# The scene for in_window.py: Suzanne alone, selected and active.
bpy.data.objects.remove(cube)
for o in (high, cage):
    o.hide_set(True)
    o.hide_render = True
select(low)
bpy.ops.wm.save_as_mainfile(filepath=os.path.join(OUT, "scene.blend"))

with open(os.path.join(OUT, "results.json"), "w") as f:
    json.dump(results, f, indent=1)
