# SPDX-License-Identifier: Apache-2.0
"""The tasks of each ao.batch command, built on the client: for every mesh, view or frame, the
library call a worker will make, its outputs under --out-dir, and the provenance record those
outputs will carry. Every request is checked by the library here, as the worker will run it, so
a bad parameter, method or output name is found once, before anything is submitted.
"""

import json
import math
import os

from . import _ao
from ._batch_plan import Refused, confined, meshes

BAKE_KINDS = {"map": "-ao.{format}", "per_vertex": "-ao.{per_vertex}", "bent_normals": "-bent.png", "thickness": "-thickness.png",
              "cavity": "-cavity.png", "gltf": "-ao.glb"}


def _params(pairs):
    """-p key=value pairs: the value as JSON when it parses (numbers, true, lists), else a string."""
    params = {}
    for pair in pairs or []:
        key, sep, value = pair.partition("=")
        if not sep or not key:
            raise Refused(f"-p {pair}: expected key=value")
        try:
            params[key] = json.loads(value)
        except ValueError:
            params[key] = value
    return params


def _checked(what, fn):
    """fn() with the library's bad-input errors as Refused naming `what`."""
    import ao
    try:
        return fn()
    except (ao.InputError, TypeError, ValueError) as e:
        raise Refused(f"{what}: {e}" if what else str(e))


def _task(kind, name, outputs, call, record):
    return {"kind": kind, "name": name, "outputs": outputs, "call": call, "record": record}


def bake_tasks(args):
    """One task per mesh: its map (--format), and with --per-vertex, --bent-normals, --thickness,
    --cavity, --gltf those files too, as OUT/<stem>-ao.png, -ao.ply, -bent.png, -thickness.png,
    -cavity.png, -ao.glb."""
    import ao
    wanted = {"map": not args.no_map, "per_vertex": bool(args.per_vertex), "bent_normals": args.bent_normals, "thickness": args.thickness,
              "cavity": args.cavity, "gltf": args.gltf}
    if not any(wanted.values()):
        raise Refused("--no-map: name another output (--per-vertex, --gltf)")
    options = _params(args.param)
    tasks = []
    for mesh, stem in meshes(args.input, args.list, args.recursive):
        files = {kind: os.path.join(args.out_dir, stem + BAKE_KINDS[kind].format(format=args.format, per_vertex=args.per_vertex))
                 for kind, on in wanted.items() if on}
        os.makedirs(os.path.dirname(files[next(iter(files))]), exist_ok=True)
        request = _checked("", lambda: ao._bake_request(
            size=args.size, method=args.method, uv_set=args.uv_set, padding=None, vertex_resolution=None, seed=args.seed,
            params=dict(options), map=wanted["map"], per_vertex=wanted["per_vertex"], output=files.get("map"),
            per_vertex_output=files.get("per_vertex"), bent_normals_output=files.get("bent_normals"), gltf_output=files.get("gltf"),
            png_bits=None, provenance=True, thickness_output=files.get("thickness"), cavity_output=files.get("cavity"),
            bent_normals_space=args.bent_normals_space, thickness_distance=args.thickness_distance, cavity_distance=args.cavity_distance))
        record = _checked("", lambda: _ao.bake_record(mesh, request))
        tasks.append(_task("bake", stem + os.path.splitext(mesh)[1], list(files.values()), {"mesh": mesh, "request": request}, record))
    return tasks


def _turntable(spec, frames, source):
    camera = spec.get("camera")
    if not isinstance(frames, int) or isinstance(frames, bool) or frames < 1:
        raise Refused(f"{source}: turntable: expected a number of frames >= 1, got {frames!r}")
    if not isinstance(camera, dict) or "eye" not in camera:
        raise Refused(f"{source}: a turntable needs camera.eye (it circles camera.target about y)")
    eye, target = camera["eye"], camera.get("target", [0, 0, 0])
    dx, dz = eye[0] - target[0], eye[2] - target[2]
    r, a0 = math.hypot(dx, dz), math.atan2(dz, dx)
    views = []
    for k in range(frames):
        a = a0 + 2 * math.pi * k / frames
        cam = dict(camera, eye=[target[0] + r * math.cos(a), eye[1], target[2] + r * math.sin(a)], target=target)
        views.append(dict(spec, camera=cam, output=f"{spec.get('output', 'frame')}-{k:04d}.{spec.get('format', 'exr')}"))
    return views


def _views(path):
    try:
        with open(path, encoding="utf-8") as f:
            spec = json.load(f)
    except (OSError, ValueError) as e:
        raise Refused(f"{path}: {getattr(e, 'strerror', None) or e}")
    if isinstance(spec, dict) and "turntable" in spec:
        spec = dict(spec)
        return _turntable(spec, spec.pop("turntable"), path)
    if isinstance(spec, list) and all(isinstance(v, dict) for v in spec):
        return spec
    raise Refused(f'{path}: expected a list of views or {{"turntable": N, "scene": ..., "camera": ...}}')


_VIEW_FILES = ("output", "shaded", "gbuffer_output")


def render_tasks(args):
    """One task per view of a views file: ao.render's arguments, every file it writes (output,
    shaded, gbuffer_output, and with extras the method's extra images) confined to --out-dir."""
    import ao
    tasks = []
    base = os.path.dirname(os.path.abspath(args.input))
    for k, view in enumerate(_views(args.input)):
        what = f"{args.input}: view {k}"
        view = {key: value for key, value in view.items() if key != "format"}
        if "output" not in view:
            raise Refused(f"{what} names no output")
        files = {key: confined(args.out_dir, view[key], f"{what}: {key}") for key in _VIEW_FILES if view.get(key) is not None}
        for path in files.values():
            os.makedirs(os.path.dirname(path), exist_ok=True)
        scene = view.get("scene")
        if isinstance(scene, str) and not os.path.isabs(scene) and os.path.exists(os.path.join(base, scene)):
            scene = os.path.join(base, scene)  # a mesh file next to the views file
        kwargs = {key: value for key, value in view.items() if key not in ("scene", "camera", *_VIEW_FILES)}
        method = kwargs.pop("method", "raytraced")
        known = ("spp", "target_error", "seed", "radius", "radius_fraction", "membership", "tau", "normal", "png_bits", "extras")
        settings = {key: kwargs.pop(key) for key in known if key in kwargs}
        settings.setdefault("seed", args.seed)
        request = _checked(what, lambda: ao._render_request(
            method, kwargs, camera=view.get("camera"), output=files["output"], shaded=files.get("shaded"),
            gbuffer_output=files.get("gbuffer_output"), provenance=True, spp=settings.get("spp"), target_error=settings.get("target_error"),
            seed=settings["seed"], radius=settings.get("radius"), radius_fraction=settings.get("radius_fraction"),
            membership=settings.get("membership"), tau=settings.get("tau"), normal=settings.get("normal"), png_bits=settings.get("png_bits", 8),
            extras=settings.get("extras", False)))
        record = _checked(what, lambda: _ao.render_record(scene, None, request))
        outputs = list(files.values()) + _extra_outputs(method, files["output"], settings.get("extras", False))
        tasks.append(_task("render", view["output"], outputs, {"scene": scene, "request": request}, record))
    return tasks


def _extra_outputs(method, output, extras):
    """The method's extra images beside `output` (<stem>-<name><ext>) when extras are asked for."""
    if not extras:
        return []
    stem, ext = os.path.splitext(output)
    return [f"{stem}-{name}{ext}" for name in _extra_names(method)]


def _extra_names(method):
    for m in _ao.methods():
        if m["name"] == method:
            return m.get("extras", [])
    return []


def compare_tasks(args):
    """One task per mesh: ao.compare's rows as OUT/<stem>-compare.json; OUT/table.json joins them."""
    import ao
    methods = args.methods.split(",") if args.methods else None
    known = [m["name"] for m in ao.methods()]
    for m in methods or []:
        if m not in known:
            raise Refused(f"--methods: unknown method '{m}' (known: {', '.join(known)}){_ao.did_you_mean(m, known)}")
    if not 1 <= args.spp_reference <= 1 << 20:
        raise Refused(f"--spp-reference must be in [1, 1048576], got {args.spp_reference}")
    request = {"methods": methods, "spp_reference": args.spp_reference, "seed": args.seed}
    request = {k: v for k, v in request.items() if v is not None}
    tasks = []
    for mesh, stem in meshes(args.input, args.list, args.recursive):
        out = os.path.join(args.out_dir, stem + "-compare.json")
        os.makedirs(os.path.dirname(out), exist_ok=True)
        record = {"ao": _ao.build_info(), "job": "compare", "inputs": [{"role": "mesh", "path": mesh}], "settings": request}
        tasks.append(_task("compare", stem + os.path.splitext(mesh)[1], [out], {"mesh": mesh, "request": request}, record))
    return tasks


def compare_table(out_dir, tasks):
    """OUT/table.json: the rows of every mesh's comparison, each with its mesh."""
    rows = []
    for task in tasks:
        path = task["outputs"][0]
        if os.path.isfile(path):
            with open(path, encoding="utf-8") as f:
                part = json.load(f)
            rows += [dict(row, mesh=part["mesh"]) for row in part["rows"]]
    _ao.write_text(os.path.join(out_dir, "table.json"), json.dumps({"ao": _ao.build_info(), "rows": rows}, indent=1) + "\n")
