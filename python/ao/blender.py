# SPDX-License-Identifier: Apache-2.0
"""Installs ao's Blender add-on: `/usr/bin/python3 -m ao.blender install` (docs/bake.md, "From Blender").

The add-on itself is part of this package (ao/_blender_addon.py, with ao/_blender_mesh.py), so it
is installed with it and runs the same ao. Blender finds add-ons only in its scripts folders, so
the command writes a small add-on file, ao_bake.py, into Blender's user add-on folder (asked from
Blender, which honours BLENDER_USER_SCRIPTS): it puts this package's folder on Blender's sys.path
(Blender does not read ~/.local or a virtual environment) and loads the add-on from it. Then it
enables the add-on in Blender's user preferences (BLENDER_USER_CONFIG) and saves them, so the next
Blender started has it. Blender must run the Python this package was built for (Debian's Blender
runs Debian's python3).

    python3 -m ao.blender install [--blender PATH] [--no-enable]
    python3 -m ao.blender uninstall [--blender PATH]
"""

import argparse
import os
import subprocess
import sys

ADDON_MODULE = "ao_bake"  # the add-on's name in Blender (the file ao_bake.py, the preferences' entry)

# The add-on's description; Blender reads it from the add-on file's source without running it, so
# it is written into ao_bake.py as a literal.
BL_INFO = {
    "name": "ao bake",
    "author": "the ao project",
    "version": (1, 0, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Render > ao Bake; Object > ao Bake",
    "description": "Bakes ambient occlusion with ao into a float image <object>_ao: single mesh or selected to active, cage or extrusion",
    "category": "Render",
}


def addon_source(package_parent):
    """The text of ao_bake.py: Blender's add-on that loads ao's from `package_parent`."""
    return (f"# Blender's add-on \"ao bake\", written by `python3 -m ao.blender install`: it loads the add-on of the Python\n"
            f"# package ao (ao/_blender_addon.py) installed in the folder below.\n"
            f"bl_info = {BL_INFO!r}\n\n"
            f"import sys\n\n"
            f"_PACKAGE_PARENT = {package_parent!r}\n"
            f"if _PACKAGE_PARENT not in sys.path:\n"
            f"    sys.path.append(_PACKAGE_PARENT)\n\n"
            f"from ao._blender_addon import register, unregister  # noqa: E402,F401\n")


# Run inside Blender (`blender -b --python-expr`): writes or removes the add-on file in the user
# add-on folder, enables or disables it, and saves the user preferences.
_IN_BLENDER = """
import os, sys, addon_utils, bpy
folder = bpy.utils.user_resource("SCRIPTS", path="addons", create=True)
path = os.path.join(folder, {module!r} + ".py")
source = {source!r}
if source:
    with open(path + ".tmp", "w", encoding="utf-8") as f:
        f.write(source)
    os.replace(path + ".tmp", path)
    if folder not in sys.path:  # Blender adds the user add-on folder at start-up when it exists
        sys.path.append(folder)
    addon_utils.modules_refresh()
    if {enable!r}:
        mod = addon_utils.enable({module!r}, default_set=True, handle_error=lambda e: sys.exit("ao.blender: " + repr(e)))
        if mod is None:
            sys.exit("ao.blender: Blender could not enable " + path)
else:
    addon_utils.disable({module!r}, default_set=True)
    if os.path.exists(path):
        os.remove(path)
if {enable!r} or not source:
    bpy.ops.wm.save_userpref()
print("ao.blender:", path)
"""


def _blender(blender, code):
    """Runs `code` in Blender in the background; its "ao.blender:" line, or SystemExit with Blender's error."""
    try:
        p = subprocess.run([blender, "-b", "--python-exit-code", "1", "--python-expr", code], capture_output=True, text=True, timeout=300)
    except FileNotFoundError:
        raise SystemExit(f"ao.blender: {blender}: Blender not found (install Debian's blender, or name it with --blender)")
    lines = [line for line in (p.stdout + p.stderr).splitlines() if line.startswith("ao.blender:")]
    if p.returncode != 0 or not lines:
        raise SystemExit(f"ao.blender: {blender} failed ({p.returncode}): " + (lines[-1] if lines else (p.stderr or p.stdout).strip()[-2000:]))
    return lines[-1][len("ao.blender: "):]


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m ao.blender", description="Installs or removes ao's Blender add-on (ao bake).")
    parser.add_argument("action", choices=["install", "uninstall"])
    parser.add_argument("--blender", default="blender", help="the Blender to install into (default: blender on PATH)")
    parser.add_argument("--no-enable", action="store_true", help="install the add-on file only; enable it in Preferences > Add-ons")
    args = parser.parse_args(argv)
    package_parent = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    source = addon_source(package_parent) if args.action == "install" else ""
    path = _blender(args.blender, _IN_BLENDER.format(module=ADDON_MODULE, source=source, enable=not args.no_enable))
    if args.action == "install":
        print(f"installed {path}" + ("" if args.no_enable else f" and enabled it; in Blender: Properties > Render > ao Bake"))
    else:
        print(f"removed {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
