# SPDX-License-Identifier: Apache-2.0
"""Runs in Blender with a window (`xvfb-run blender --enable-event-simulate scene.blend --python
in_window.py -- OUT_DIR`) for test_addon.py: the operator as the panel's button runs it (modal, a
thread, progress in the status bar), a bake to the end and one cancelled by a simulated Esc. Writes
window.json (what happened) and window.png (a screenshot: the panel and the baked image).
"""

import json
import os
import sys
import threading
import time

import bpy

OUT = sys.argv[sys.argv.index("--") + 1]
results = {}
window = bpy.context.window_manager.windows[0]
steps = []


def area(kind):
    return next(a for a in window.screen.areas if a.type == kind)


def override(kind="VIEW_3D"):
    a = area(kind)
    return bpy.context.temp_override(window=window, area=a, region=next(r for r in a.regions if r.type == "WINDOW"))


def baking():
    return any(t.name == "ao bake" for t in threading.enumerate())


def guarded(step):
    """`step` for Blender's timer: an exception ends the session, recorded, instead of leaving it open."""
    def run():
        try:
            return step()
        except Exception as e:
            results["error"] = f"{step.__name__}: {e!r}"
            finish()
            return None
    run.__name__ = step.__name__
    return run


def wait(until, seconds, then):
    """Calls `then` once `until()` holds, or records a time-out; polled by Blender's timer."""
    start = time.monotonic()

    def poll():
        if until():
            then(time.monotonic() - start)
            return None
        if time.monotonic() - start > seconds:
            results["timed_out"] = then.__name__
            finish()
            return None
        return 0.05
    bpy.app.timers.register(guarded(poll))


def start_bake():
    # The panel in view: Properties on the Render tab; the timeline becomes an image editor.
    area("PROPERTIES").spaces.active.context = "RENDER"
    bpy.context.scene.ao_bake.size = 256
    bpy.context.scene.ao_bake.samples = 32
    with override():
        results["invoke"] = sorted(bpy.ops.object.ao_bake("INVOKE_DEFAULT"))
    wait(lambda: not baking() and "Suzanne_ao" in bpy.data.images, 60, baked)


def baked(seconds):
    image = bpy.data.images["Suzanne_ao"]
    results["modal"] = {"seconds": seconds, "size": list(image.size), "float": image.is_float}
    # For the screenshot: the image on Suzanne (an image texture node, the viewport's solid mode
    # showing textures, flat light), seen from the front.
    material = bpy.data.materials.new("ao")
    material.use_nodes = True
    texture = material.node_tree.nodes.new("ShaderNodeTexImage")
    texture.image = image
    material.node_tree.links.new(texture.outputs["Color"], material.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
    material.node_tree.nodes.active = texture
    suzanne = bpy.data.objects["Suzanne"]
    suzanne.data.materials.append(material)
    shading = area("VIEW_3D").spaces.active.shading
    shading.color_type, shading.light = "TEXTURE", "FLAT"
    with override():
        bpy.ops.view3d.view_axis(type="FRONT")
        bpy.ops.view3d.view_selected()
    # The panel as a popup beside Suzanne (the simulated mouse places it).
    window.event_simulate(type="MOUSEMOVE", value="NOTHING", x=900, y=690)
    bpy.app.timers.register(guarded(show_panel), first_interval=0.3)
    bpy.app.timers.register(guarded(screenshot), first_interval=1.5)


def show_panel():
    with override():
        bpy.ops.wm.call_panel(name="AO_PT_bake", keep_open=True)


def screenshot():
    with override():
        bpy.ops.screen.screenshot(filepath=os.path.join(OUT, "window.png"))
    bpy.data.objects["Suzanne"].data.materials.clear()
    bpy.data.images.remove(bpy.data.images["Suzanne_ao"])
    with override():
        results["invoke_long"] = sorted(bpy.ops.object.ao_bake("INVOKE_DEFAULT", size=1024, samples=4096))
    results["long_running"] = baking()
    bpy.app.timers.register(guarded(press_esc), first_interval=0.5)


def press_esc():
    results["esc_at"] = time.monotonic()
    window.event_simulate(type="ESC", value="PRESS")
    window.event_simulate(type="ESC", value="RELEASE")
    wait(lambda: not baking(), 30, cancelled)


def cancelled(seconds):
    results["cancel"] = {"seconds": seconds}
    bpy.app.timers.register(guarded(after_cancel), first_interval=2.0)  # the modal ends at its next timer event (0.1 s)


def after_cancel():
    results["cancel"]["image"] = "Suzanne_ao" in bpy.data.images
    finish()


def finish():
    with open(os.path.join(OUT, "window.json"), "w") as f:
        json.dump(results, f, indent=1)
    bpy.ops.wm.quit_blender()


bpy.app.timers.register(guarded(start_bake), first_interval=1.0)
