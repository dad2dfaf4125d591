# SPDX-License-Identifier: Apache-2.0
# Makes the low mesh of a high-to-low bake case: the high mesh decimated (Blender's Decimate
# modifier, collapse) to a fraction of its triangles, smooth-shaded, with UVs: the high mesh's own
# where it has them (decimation keeps them), else Smart UV Project's charts. Run by
# bench/blender/compare.sh; by hand:
#   blender -b --factory-startup --python bench/blender/make_low.py -- HIGH.obj|HIGH.off RATIO LOW.obj
# Writes LOW.obj (positions, UVs, normals) in the input's coordinates and prints "triangles N".
import os
import sys

import bpy

args = sys.argv[sys.argv.index("--") + 1:]
high_path, ratio, low_path = args[0], float(args[1]), args[2]

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mesh_io import load_mesh  # noqa: E402

bpy.ops.wm.read_factory_settings(use_empty=True)
obj, axes = load_mesh(high_path, "high")
bpy.context.view_layer.objects.active = obj
obj.select_set(True)

decimate = obj.modifiers.new("decimate", "DECIMATE")
decimate.decimate_type = "COLLAPSE"
decimate.ratio = ratio
decimate.use_collapse_triangulate = True
bpy.ops.object.modifier_apply(modifier=decimate.name)
bpy.ops.object.shade_smooth()
if not obj.data.uv_layers:
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="SELECT")
    bpy.ops.uv.smart_project(angle_limit=1.15, island_margin=0.01)
    bpy.ops.object.mode_set(mode="OBJECT")
print(f"triangles {sum(len(p.vertices) - 2 for p in obj.data.polygons)}")
bpy.ops.wm.obj_export(filepath=low_path, export_selected_objects=True, export_uv=True, export_normals=True, export_materials=False,
                      export_triangulated_mesh=True, **axes)
