# SPDX-License-Identifier: Apache-2.0
"""ao's Blender add-on (installed by `python3 -m ao.blender install`; docs/bake.md, "From Blender").

bpy.ops.object.ao_bake bakes the ambient occlusion of the active mesh object into its UV map with
ao's ray-traced baker, as `ao bake` does, into a float image named "<object name>_ao" (non-colour
data, V in red, green and blue, 1 in alpha); on request also the rest of the AO family, each a
float image of its own: "<object name>_bent" (bent normals in tangent space, n * 0.5 + 0.5 in RGB,
for the Normal Map node), "_thickness" and "_cavity". The mesh goes from Blender's own data (modifiers
applied, world space, Blender's shading normals, the active UV map) through numpy into
ao.Scene.from_arrays (ao/_blender_mesh.py): no file is written. With selected_to_active the AO of
the other selected mesh objects is baked into the active one's UVs (`ao bake --high`), rays from a
cage object or from the active mesh pushed out by cage_extrusion, as Blender's own bake panel
offers.

From the panel (Properties > Render > ao Bake) or a menu the operator runs modal: the bake runs on
a thread (ao releases Python's lock while it computes), the window stays live, progress shows in
the status bar and Esc cancels within a fraction of a second, leaving no image. From a script
(`bpy.ops.object.ao_bake(size=512, samples=64)`, also `blender -b`) it runs to the end and
returns; cancel() stops it from another thread. Errors are reported as Blender reports them
({'ERROR'}, the line ao gives) and the operator returns {'CANCELLED'}.
"""

import threading
import warnings

import bpy  # type: ignore[import]  # Blender's module: this file runs inside Blender only
import numpy as np

import ao

from . import _blender_mesh as mesh_data

# The options, each declared once: the operator's properties and the panel's scene settings
# (Scene.ao_bake) are made from this table. Defaults and ranges are `ao bake`'s.
_MEMBERSHIPS = [("step", "Step", "Classical AO: an occluder within the distance counts fully"),
                ("linear", "Linear", "Occluders count by d / distance"),
                ("sqrt", "Square root", "Occluders count by sqrt(d / distance)"),
                ("cubic", "Cubic", "Occluders count by (d / distance)^3")]
_OPTIONS = [
    ("size", bpy.props.IntProperty, dict(name="Size", default=1024, min=1, max=16384, soft_max=8192, description="Texels per side of the image (ao bake --size)")),
    ("samples", bpy.props.IntProperty, dict(name="Rays", default=64, min=1, max=1 << 20, soft_max=4096, description="Rays per texel (ao bake --samples)")),
    ("max_distance", bpy.props.FloatProperty, dict(name="Distance", default=0.0, min=0.0, subtype="DISTANCE", unit="LENGTH",
                                                   description="Occluders count only within this distance, world units; 0 = unlimited (ao bake --max-distance)")),
    ("membership", bpy.props.EnumProperty, dict(name="Falloff", items=_MEMBERSHIPS, default="step", description="Falloff within the distance (ao bake --membership)")),
    ("denoise", bpy.props.FloatProperty, dict(name="Filter", default=1.5, min=0.0, max=4.0, description="Sigma of the texture-space filter, texels; 0 = off (ao bake --denoise)")),
    ("padding", bpy.props.IntProperty, dict(name="Padding", default=16, min=0, max=1024, subtype="PIXEL", description="Texels filled outside the UV islands (ao bake --padding)")),
    ("seed", bpy.props.IntProperty, dict(name="Seed", default=1, min=0, description="Seed of the texels' sample sets (ao bake --seed)")),
    ("ignore_back_faces", bpy.props.BoolProperty, dict(name="Ignore Back Faces", default=False, description="Rays pass through back faces (ao bake -p ignore_back_faces=true)")),
    ("spread_angle", bpy.props.FloatProperty, dict(name="Spread", default=180.0, min=0.001, max=180.0,
                                                   description="Full angle, degrees, of the cone of directions about the normal; 180 = the hemisphere (ao bake --spread-angle)")),
    ("bent_normals", bpy.props.BoolProperty, dict(name="Bent Normals", default=False,
                                                  description="Also bake <object>_bent: the average open direction in tangent space, as the Normal Map node reads it (ao bake --bent-normals --bent-normals-space tangent)")),
    ("thickness", bpy.props.BoolProperty, dict(name="Thickness", default=False,
                                               description="Also bake <object>_thickness: rays into the mesh, white where it is at least the thickness distance deep (ao bake --thickness)")),
    ("thickness_distance", bpy.props.FloatProperty, dict(name="Thickness Distance", default=0.25, min=0.0001, max=10.0,
                                                         description="R of the thickness, a fraction of the mesh's bounding-box diagonal (ao bake --thickness-distance)")),
    ("cavity", bpy.props.BoolProperty, dict(name="Cavity", default=False,
                                            description="Also bake <object>_cavity: AO within the cavity distance, the small creases only (ao bake --cavity)")),
    ("cavity_distance", bpy.props.FloatProperty, dict(name="Cavity Distance", default=0.02, min=0.0001, max=10.0,
                                                      description="R of the cavity, a fraction of the mesh's bounding-box diagonal (ao bake --cavity-distance)")),
    ("uv_map", bpy.props.StringProperty, dict(name="UV Map", default="", description="The UV map to bake into; empty = the active one")),
    ("selected_to_active", bpy.props.BoolProperty, dict(name="Selected to Active", default=False,
                                                        description="Bake the AO of the selected mesh objects into the active one's UVs (ao bake --high)")),
    ("cage_object", bpy.props.StringProperty, dict(name="Cage Object", default="",
                                                   description="Cage: an object with the active mesh's topology, pushed out; rays start on it and travel inwards (ao bake --cage)")),
    ("cage_extrusion", bpy.props.FloatProperty, dict(name="Extrusion", default=0.0, min=0.0, subtype="DISTANCE", unit="LENGTH",
                                                     description="Without a cage object: the active mesh pushed out by this distance; 0 = ao's default, fitted to the pair (ao bake --cage-extrusion)")),
    ("max_back", bpy.props.FloatProperty, dict(name="Max Ray Distance", default=0.0, min=0.0, subtype="DISTANCE", unit="LENGTH",
                                               description="How far inside the active mesh a ray still looks for the selected ones; 0 = as far as the cage is outside (ao bake --max-back)")),
]


class Cancelled(Exception):
    """Raised by the progress function when the bake is cancelled (Esc, or cancel())."""


_cancel = threading.Event()


def cancel():
    """Stops the bake that is running (what Esc does): it ends within a fraction of a second and
    leaves no image."""
    _cancel.set()


def _error(message):
    return ao.InputError(message)


def _object_arrays(obj, depsgraph, uv_map="", uvs=True):
    """The evaluated mesh of `obj` (modifiers applied) as welded world-space arrays; and, for a
    cage, the Blender vertex of each ao vertex."""
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        mesh.calc_loop_triangles()
        mesh.calc_normals_split()
        if uvs and mesh_data.uv_layer(mesh, uv_map) is None:
            raise _error(f"{obj.name}: the mesh has no UV map" + (f" named '{uv_map}'" if uv_map else "") + "; add one (UV > Unwrap) to bake into")
        if len(mesh.loop_triangles) == 0:
            raise _error(f"{obj.name}: the mesh has no faces")
        positions, normals, corner_uvs, vertex_of_corner = mesh_data.corners(mesh, obj.matrix_world, uv_map if uvs else None)
        counts = (len(mesh.vertices), len(mesh.loops))
    finally:
        evaluated.to_mesh_clear()
    v, n, t, faces, corner = mesh_data.weld(positions, normals, corner_uvs if uvs else None)
    return dict(vertices=v, faces=faces, normals=n, uvs=t), vertex_of_corner[corner], counts


def _cage_scene(cage, low_vertex, low_faces, low_counts, depsgraph):
    """The cage object's world positions at the active mesh's welded vertices: a scene with the
    active mesh's topology (Blender's cage must have the same vertices and loops)."""
    evaluated = cage.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        if (len(mesh.vertices), len(mesh.loops)) != low_counts:
            raise _error(f"cage {cage.name}: {len(mesh.vertices)} vertices and {len(mesh.loops)} loops, the active mesh has "
                         f"{low_counts[0]} and {low_counts[1]}; a cage is the active mesh's copy pushed out")
        co = np.empty(len(mesh.vertices) * 3, np.float32)
        mesh.vertices.foreach_get("co", co)
    finally:
        evaluated.to_mesh_clear()
    m = np.array(cage.matrix_world, dtype=np.float64)
    world = (co.reshape(-1, 3)[low_vertex].astype(np.float64) @ m[:3, :3].T + m[:3, 3]).astype(np.float32)
    return ao.Scene.from_arrays(world, low_faces, name=cage.name)


def _high_scene(objects, depsgraph):
    """The selected meshes as one scene (their UVs are not used)."""
    parts = [_object_arrays(o, depsgraph, uvs=False)[0] for o in objects]
    offsets = np.cumsum([0] + [len(p["vertices"]) for p in parts[:-1]])
    vertices = np.concatenate([p["vertices"] for p in parts])
    normals = np.concatenate([p["normals"] for p in parts])
    faces = np.concatenate([p["faces"] + k for p, k in zip(parts, offsets)])
    return ao.Scene.from_arrays(vertices, faces, normals=normals, name=", ".join(o.name for o in objects))


def prepare(context, options):
    """Everything read from Blender (on its main thread): (image name, ao.bake's arguments).
    ao.InputError naming the object for what cannot be baked."""
    low = context.active_object
    if low is None or low.type != "MESH":
        raise _error("ao bake: make the mesh object to bake into the active object")
    depsgraph = context.evaluated_depsgraph_get()
    arrays, low_vertex, counts = _object_arrays(low, depsgraph, options.uv_map)
    scene = ao.Scene.from_arrays(name=low.name, **arrays)
    args = dict(size=options.size, padding=options.padding, seed=options.seed, samples=options.samples, denoise=options.denoise,
                membership=options.membership, ignore_back_faces=options.ignore_back_faces)
    if options.spread_angle < 180.0:
        args["spread_angle"] = options.spread_angle
    if options.bent_normals:
        args.update(bent_normals=True, bent_normals_space="tangent")
    if options.thickness:
        args.update(thickness=True, thickness_distance=options.thickness_distance)
    if options.cavity:
        args.update(cavity=True, cavity_distance=options.cavity_distance)
    if options.max_distance > 0:
        args["max_distance"] = options.max_distance
    if options.selected_to_active:
        high = [o for o in context.selected_objects if o != low and o.type == "MESH"]
        if not high:
            raise _error("ao bake: Selected to Active needs the high-poly mesh objects selected besides the active one")
        args["high"] = _high_scene(high, depsgraph)
        if options.cage_object:
            cage = bpy.data.objects.get(options.cage_object)
            if cage is None or cage.type != "MESH":
                raise _error(f"ao bake: cage object '{options.cage_object}' is not a mesh object of this file")
            args["cage"] = _cage_scene(cage, low_vertex, arrays["faces"], counts, depsgraph)
        elif options.cage_extrusion > 0:
            args["cage_extrusion"] = options.cage_extrusion
        if options.max_back > 0:
            args["max_back"] = options.max_back
    elif options.cage_object or options.cage_extrusion > 0 or options.max_back > 0:
        raise _error("ao bake: Cage Object, Extrusion and Max Ray Distance need Selected to Active (the high-poly objects to bake from)")
    return low.name + "_ao", scene, args


def run(scene, args, progress=None):
    """ao.bake of the prepared mesh (any thread): its full result and its warnings. `progress`
    (optional) gets the fraction done; Cancelled when cancel() was called."""
    def report(stage, done, total):
        if _cancel.is_set():
            raise Cancelled()
        if progress is not None and total:
            progress(done / total)

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = ao.bake(scene, full=True, progress=report, **args)
    return out, [str(w.message) for w in caught]


def store(name, visibility, pixels=None):
    """The map into the float image `name` (made, or resized and overwritten), as non-colour data;
    `pixels`: Blender's pixels when not the map's grey (map_to_pixels)."""
    height, width = visibility.shape[:2]
    image = bpy.data.images.get(name)
    if image is None:
        image = bpy.data.images.new(name, width, height, alpha=False, float_buffer=True)
    elif image.source == "GENERATED":
        image.generated_width, image.generated_height = width, height
        image.use_generated_float = True
    elif not image.is_float:
        raise _error(f"ao bake: the image '{name}' is an 8-bit image from a file; remove or rename it to bake a float image")
    elif tuple(image.size) != (width, height):
        image.scale(width, height)
    image.colorspace_settings.name = "Non-Color"
    image.pixels.foreach_set(mesh_data.map_to_pixels(visibility) if pixels is None else pixels)
    image.update()
    return image


def _summary(name, out):
    s = out["summary"]
    return f"ao: baked {name}: {s['width']}x{s['height']}, {s['texels_covered']} texels covered, mean V = {s['mean_visibility']:.4f}"


class AO_OT_bake(bpy.types.Operator):
    """Bake ambient occlusion with ao into the float image <object>_ao"""

    bl_idname = "object.ao_bake"
    bl_label = "ao Bake"
    bl_options = {"REGISTER"}

    _thread = None

    @classmethod
    def poll(cls, context):
        return context.active_object is not None and context.active_object.type == "MESH"

    def _begin(self, context):
        """The bake's inputs, or None after reporting why there are none."""
        _cancel.clear()
        try:
            return prepare(context, self)
        except (ao.InputError, TypeError, OSError) as e:
            self.report({"ERROR"}, str(e))
            return None

    def _finish(self, name, out, warned, error):
        if isinstance(error, Cancelled):
            self.report({"WARNING"}, "ao: bake cancelled")
            return {"CANCELLED"}
        if error is not None:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        for w in warned:
            self.report({"WARNING"}, w)
        try:
            store(name, out["map"])
            base = name[: -len("_ao")]
            for key in ("thickness", "cavity"):
                if key in out:
                    store(base + "_" + key, out[key])
            if "bent_normals" in out:
                store(base + "_bent", out["bent_normals"], mesh_data.vectors_to_pixels(out["bent_normals"]))
        except ao.InputError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        self.report({"INFO"}, _summary(name, out))
        return {"FINISHED"}

    def execute(self, context):
        prepared = self._begin(context)
        if prepared is None:
            return {"CANCELLED"}
        name, scene, args = prepared
        wm = context.window_manager
        wm.progress_begin(0, 1000)
        try:
            out, warned = run(scene, args, lambda f: wm.progress_update(int(1000 * f)))
            error = None
        except (Cancelled, ao.InputError, TypeError, OSError) as e:
            out, warned, error = None, [], e
        finally:
            wm.progress_end()
        return self._finish(name, out, warned, error)

    def invoke(self, context, event):
        settings = context.scene.ao_bake
        for key, _, _ in _OPTIONS:  # the panel's settings, where the caller did not set the option
            if not self.properties.is_property_set(key):
                setattr(self, key, getattr(settings, key))
        prepared = self._begin(context)
        if prepared is None:
            return {"CANCELLED"}
        self._name, scene, args = prepared
        self._state = {"fraction": 0.0, "out": None, "warned": [], "error": None}

        def work():
            try:
                self._state["out"], self._state["warned"] = run(scene, args, lambda f: self._state.__setitem__("fraction", f))
            except (Cancelled, ao.InputError, TypeError, OSError) as e:
                self._state["error"] = e

        self._thread = threading.Thread(target=work, name="ao bake", daemon=True)
        self._thread.start()
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, 1000)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC":
            cancel()
            return {"RUNNING_MODAL"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        wm = context.window_manager
        if self._thread.is_alive():
            percent = 100 * self._state["fraction"]
            wm.progress_update(int(10 * percent))
            if context.workspace is not None:
                context.workspace.status_text_set(f"ao: baking {self._name}: {percent:.0f}% (Esc cancels)")
            return {"RUNNING_MODAL"}
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)
        return self._finish(self._name, self._state["out"], self._state["warned"], self._state["error"])


class AO_PG_settings(bpy.types.PropertyGroup):
    """The panel's bake settings (Scene.ao_bake): what the button bakes with."""


class AO_PT_bake(bpy.types.Panel):
    bl_label = "ao Bake"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        s = context.scene.ao_bake
        obj = context.active_object
        layout.operator(AO_OT_bake.bl_idname, icon="RENDER_STILL",
                        text=f"Bake {obj.name}_ao" if obj is not None and obj.type == "MESH" else "ao Bake")
        col = layout.column()
        for key in ("size", "samples", "max_distance", "membership", "denoise", "padding", "seed", "ignore_back_faces", "spread_angle"):
            col.prop(s, key)
        col = layout.column(heading="Also Bake")
        col.prop(s, "bent_normals")
        col.prop(s, "thickness")
        sub = col.column()
        sub.active = s.thickness
        sub.prop(s, "thickness_distance")
        col.prop(s, "cavity")
        sub = col.column()
        sub.active = s.cavity
        sub.prop(s, "cavity_distance")
        if obj is not None and obj.type == "MESH":
            col.prop_search(s, "uv_map", obj.data, "uv_layers")
        col = layout.column(heading="Selected to Active")
        col.prop(s, "selected_to_active", text="")
        sub = col.column()
        sub.active = s.selected_to_active
        sub.prop_search(s, "cage_object", context.scene, "objects")
        ext = sub.column()
        ext.active = not s.cage_object
        ext.prop(s, "cage_extrusion")
        sub.prop(s, "max_back")


def _menu(self, context):
    self.layout.operator(AO_OT_bake.bl_idname)


def _annotate(cls):
    cls.__annotations__ = {key: prop(**kwargs) for key, prop, kwargs in _OPTIONS}
    return cls


_CLASSES = (_annotate(AO_PG_settings), _annotate(AO_OT_bake), AO_PT_bake)


def register():
    for c in _CLASSES:
        bpy.utils.register_class(c)
    bpy.types.Scene.ao_bake = bpy.props.PointerProperty(type=AO_PG_settings)
    bpy.types.VIEW3D_MT_object.append(_menu)


def unregister():
    bpy.types.VIEW3D_MT_object.remove(_menu)
    del bpy.types.Scene.ao_bake
    for c in reversed(_CLASSES):
        bpy.utils.unregister_class(c)
