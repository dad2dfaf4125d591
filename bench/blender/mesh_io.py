# SPDX-License-Identifier: Apache-2.0
# Loading a mesh into Blender's scene for the bench scripts: OBJ through Blender's importer (the
# file's axes kept), OFF by hand (Blender reads no OFF). Returns the object and the axis arguments
# that write it back in the file's coordinates (wm.obj_export). read_pixels: an image file's
# pixels through Blender's loader, so that maps from either baker are read the same way.
import bpy
import numpy as np


def load_mesh(path, name):
    if path.lower().endswith(".off"):
        words = open(path).read().split()
        assert words[0] == "OFF", path
        nv, nf = int(words[1]), int(words[2])
        values = words[4:]
        verts = [tuple(float(v) for v in values[3 * i:3 * i + 3]) for i in range(nv)]
        at, faces = 3 * nv, []
        for _ in range(nf):
            n = int(values[at])
            faces.append([int(v) for v in values[at + 1:at + 1 + n]])
            at += 1 + n
        mesh = bpy.data.meshes.new(name)
        mesh.from_pydata(verts, [], faces)
        mesh.polygons.foreach_set("use_smooth", [True] * len(faces))  # interpolated normals, as ao's loader gives an OFF
        obj = bpy.data.objects.new(name, mesh)
        bpy.context.scene.collection.objects.link(obj)
        return obj, dict(forward_axis="Y", up_axis="Z")  # Blender's own axes: written as read
    before = set(bpy.context.scene.objects)
    bpy.ops.import_scene.obj(filepath=path, axis_forward="-Z", axis_up="Y", split_mode="OFF")
    obj = [o for o in bpy.context.scene.objects if o.type == "MESH" and o not in before][0]
    obj.name = name
    return obj, dict(forward_axis="NEGATIVE_Z", up_axis="Y")


def bake_image(obj, name, size):
    """A float size x size image `name` (non-colour data: saved as stored, not sRGB-encoded) made the
    active image node of `obj`'s one material: where Cycles' bake writes."""
    image = bpy.data.images.new(name, width=size, height=size, float_buffer=True, alpha=False)
    image.colorspace_settings.name = "Non-Color"
    material = bpy.data.materials.new("bake")
    material.use_nodes = True
    node = material.node_tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    material.node_tree.nodes.active = node
    obj.data.materials.clear()
    obj.data.materials.append(material)
    return image


def read_pixels(path):
    """The RGBA pixels of an image file as read by Blender (non-colour data), h x w x 4 float32,
    rows from the bottom as Blender stores them."""
    image = bpy.data.images.load(path)
    image.colorspace_settings.name = "Non-Color"
    w, h = image.size
    data = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(data)
    return data.reshape(h, w, 4)
