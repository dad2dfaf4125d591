# SPDX-License-Identifier: Apache-2.0
"""ao: ambient occlusion on the CPU, from Python (README "Python").

The calls stand on the C++ library's job layer (src/ao/jobs/), the same code `ao render`, `ao bake`
and `ao compare` run, so an array from here equals the CLI's output for the same inputs and seed.

    import ao
    v = ao.render("wedge", ao.Camera(width=320, height=180), method="volumetric")  # H x W float32
    m = ao.bake(ao.Scene.from_arrays(vertices, faces, uvs=uvs), size=256)        # the AO map
    rows = ao.compare("sphere-on-plane", methods=["alchemy", "gtao"])             # list of dicts

Values: V in [0, 1] per pixel, texel or point, 1 = fully open, 0 = fully occluded. Background
pixels of a render, where no surface is seen (the G-buffer's object_id is 0), hold 1; texels of a
map beyond the charts and their padding hold 0 (bake(full=True) gives the `mask` of covered texels).

    >>> v = ao.render("plane", ao.Camera(eye=(0, 1, 3), target=(0, 1, 4), width=4, height=4), "volumetric")
    >>> float(v.min()), float(v.max())   # looking away from the plane: background only
    (1.0, 1.0)

Errors: an argument of the wrong type raises TypeError; a bad value or a bad file raises
ao.InputError (a ValueError subclass) with one line naming the argument or file ("padding must be
in [0, 1024] texels, got 2000"), the line `ao` prints after "ao: error: " with its options named
as keyword arguments; an I/O failure (disk full, permissions) raises OSError; Ctrl-C raises
KeyboardInterrupt within a fraction of a second. The GIL is released while the job computes, so
other Python threads run meanwhile. Warnings of the job (e.g. degenerate triangles dropped) are
issued with warnings.warn.

Progress: the long calls take progress=True (a tqdm bar per stage when tqdm is installed, a line
on stderr every few seconds otherwise) or a callable(stage, done, total).
"""

import functools as _functools
import os as _os

from . import _ao
from . import _arguments as _check
from ._ao import GBuffer, InputError, Scene, read_image, __version__
from ._progress import reporter as _reporter

__all__ = ["Camera", "GBuffer", "InputError", "Scene", "bake", "compare", "gbuffer", "gbuffer_from_arrays", "methods",
           "occlusion", "read_image", "render", "set_threads", "__version__"]


class Camera:
    """A pinhole camera: look-at placement, vertical field of view and image size.

    Camera(eye=None, target=None, up=None, fov=None, width=None, height=None)

    eye, target, up: 3 numbers each, world units (up default (0, 1, 0)); fov: vertical field of
    view in degrees (0, 180); width, height: pixels. A field left None takes the job's default:
    the scene's own view or auto-framing for the placement, 1280 x 720 for render (640 x 360 for
    compare). Reads and writes the camera JSON of `ao --camera` and the viewer's S key.
    """

    _fields = ("eye", "target", "up", "fov", "width", "height")

    def __init__(self, eye=None, target=None, up=None, fov=None, width=None, height=None):
        self.eye = _check.vector3("camera.eye", eye)
        self.target = _check.vector3("camera.target", target)
        self.up = _check.vector3("camera.up", up)
        self.fov = _check.number("camera.fov", fov, optional=True)
        self.width = _check.integer("camera.width", width, optional=True)
        self.height = _check.integer("camera.height", height, optional=True)

    @classmethod
    def read(cls, path):
        """Camera.read(path) -> Camera: a camera JSON file (ao.InputError naming it when bad)."""
        return cls.from_dict(_ao.read_camera(_os.fspath(path)))

    @classmethod
    def from_dict(cls, d):
        """Camera.from_dict({"eye": [..], "target": [..], "up": [..], "fov": 45, "width": .., "height": ..})."""
        if not isinstance(d, dict):
            raise TypeError(f"camera: expected a dict of camera fields, got {type(d).__name__}")
        unknown = set(d) - set(cls._fields)
        if unknown:
            raise InputError("camera: unknown field(s) " + ", ".join(sorted(unknown)) + "; the fields are " + ", ".join(cls._fields))
        return cls(**{str(k): v for k, v in d.items()})

    def to_dict(self):
        """The fields that are set, as the camera JSON names them."""
        return {k: (list(v) if isinstance(v, (tuple, list)) else v) for k in self._fields if (v := getattr(self, k)) is not None}

    def write(self, path):
        """Writes the camera JSON (atomically); every field must be set except up and the size."""
        _ao.write_camera(_os.fspath(path), self.to_dict())

    def __eq__(self, other):
        return isinstance(other, Camera) and self.to_dict() == other.to_dict()

    def __repr__(self):
        return "ao.Camera(" + ", ".join(f"{k}={v!r}" for k, v in self.to_dict().items()) + ")"


def _camera_dict(camera):
    if camera is None:
        return None
    if isinstance(camera, Camera):
        return camera.to_dict()
    if isinstance(camera, dict):
        return Camera.from_dict(camera).to_dict()
    if isinstance(camera, (str, _os.PathLike)):
        return Camera.read(camera).to_dict()
    raise TypeError(f"camera: expected an ao.Camera, a dict or a camera JSON file, got {type(camera).__name__}")


def _scene_arg(scene, name="scene"):
    if scene is None or isinstance(scene, (Scene, str)):
        return scene
    if isinstance(scene, _os.PathLike):
        return _os.fspath(scene)
    if isinstance(scene, (list, tuple)) and scene:
        return [_check.path(f"{name}[{k}]", s, optional=False) for k, s in enumerate(scene)]
    raise TypeError(f"{name}: expected a mesh file, a built-in scene name, a list of mesh files or an ao.Scene, got {type(scene).__name__}")


def _run(job, progress, *args):
    """The compiled `job` with the caller's progress (ao._progress), its display ended afterwards."""
    fn, done = _reporter(_check.progress("progress", progress))
    try:
        return job(*args, fn)
    finally:
        done()


def methods():
    """methods() -> list of dict

    Every AO method with its parameter table, the one `ao render --json`, `-p key=value` and the
    viewer use: [{"name", "summary", "ground_truth", "needs_scene", "params": [{"name", "type",
    "default", "range", "valid", "unit", "help", ("choices")}]}].
    """
    return _ao.methods()


def set_threads(threads):
    """set_threads(threads): worker threads for the calls that follow (as --threads); 0 = all cores.
    Results do not depend on it."""
    _ao.set_threads(_check.integer("threads", threads))


def render(scene=None, camera=None, method="raytraced", *, gbuffer=None, spp=None, target_error=None, seed=1, radius=None,
           radius_fraction=None, membership=None, tau=None, normal=None, output=None, shaded=None, gbuffer_output=None,
           png_bits=8, extras=False, provenance=False, full=False, progress=None, **params):
    """render(scene=None, camera=None, method="raytraced", *, gbuffer=None, spp=None, target_error=None,
           seed=1, radius=None, radius_fraction=None, membership=None, tau=None, normal=None,
           output=None, shaded=None, gbuffer_output=None, png_bits=8, extras=False,
           provenance=False, full=False, progress=None, **params)
       -> numpy.ndarray  (H x W float32, V per pixel; 1 where no surface is seen)

    Renders the AO of a scene as `ao render` does.

    scene           a mesh file, a list of them, a built-in name (default, plane, wedge,
                    sphere-on-plane, box-room, displaced) or an ao.Scene; None: "default"
    camera          an ao.Camera, a dict of its fields or a camera JSON file; None: the scene's view
                    or auto-framed, 1280 x 720
    method          "raytraced" (ground truth) or an approximate method (ao.methods())
    gbuffer         an ao.GBuffer (ao.gbuffer, ao.gbuffer_from_arrays) instead of a scene:
                    screen-space methods on the caller's own buffers
    spp             samples per pixel (the method's sample count; the maximum with target_error)
    target_error    adaptive: stop a pixel when its standard error <= this (raytraced)
    seed            seed of the per-pixel sample sets, [0, 4294967295]; same seed, same image
    radius          R, world units; default radius_fraction x the objects' diagonal
    radius_fraction R as a fraction of the objects' diagonal (default 0.1)
    membership      falloff: step (default), linear, sqrt, cubic, exp (with tau), alchemy
    normal          "shading" (default) or "geometric": the hemisphere every method integrates over
    output, shaded, gbuffer_output, png_bits, extras
                    files to write as `ao render -o, --shaded, --gbuffer-out, --png-bits, --extras`
                    write them (one atomic transaction)
    provenance      also write each file's record beside it, FILE.ao.json (`--provenance`)
    full            return a dict instead: {"visibility", "std_error" (raytraced: the standard
                    error of V per pixel), "color" (RGB methods), "extras" {name: array},
                    "summary" (what `ao render --json` prints), "gbuffer" (ao.GBuffer)}
    progress        True (a bar) or a callable(stage, done, total) (module docstring)
    **params        the method's parameters by name (`ao render -p key=value`), checked against its
                    table (listed below); a bad one raises ao.InputError (a ValueError)
    """
    if gbuffer is not None and not isinstance(gbuffer, GBuffer):
        raise TypeError(f"gbuffer: expected an ao.GBuffer (ao.gbuffer, ao.gbuffer_from_arrays), got {type(gbuffer).__name__}")
    request = _render_request(method, params, spp=spp, target_error=target_error, seed=seed, radius=radius, radius_fraction=radius_fraction,
                              membership=membership, tau=tau, normal=normal, camera=camera, output=output, shaded=shaded,
                              gbuffer_output=gbuffer_output, png_bits=png_bits, extras=extras, provenance=provenance)
    request["return_gbuffer"] = _check.flag("full", full)
    out = _run(_ao.render, progress, _scene_arg(scene), gbuffer, request)
    return out if full else out["visibility"]


def _falloff(radius, radius_fraction, membership, tau):
    return {"radius": _check.number("radius", radius, optional=True),
            "radius_fraction": _check.number("radius_fraction", radius_fraction, optional=True),
            "membership": _check.text("membership", membership, optional=True), "tau": _check.number("tau", tau, optional=True)}


def _render_request(method, params, *, spp, target_error, seed, radius, radius_fraction, membership, tau, normal, camera, output,
                    shaded, gbuffer_output, png_bits, extras, provenance):
    """The job layer's request for render() (and ao.batch's records), every argument checked."""
    request = {"method": _check.text("method", method), "params": dict(params), "samples": _check.integer("spp", spp, optional=True),
               "target_error": _check.number("target_error", target_error, optional=True), "seed": _check.seed("seed", seed),
               **_falloff(radius, radius_fraction, membership, tau), "normal": _check.text("normal", normal, optional=True),
               "camera": _camera_dict(camera), "output": _check.path("output", output), "shaded": _check.path("shaded", shaded),
               "gbuffer_output": _check.path("gbuffer_output", gbuffer_output), "png_bits": _check.integer("png_bits", png_bits),
               "extras": _check.flag("extras", extras), "provenance": _check.flag("provenance", provenance)}
    return {k: v for k, v in request.items() if v is not None}


def gbuffer(scene=None, camera=None, *, normal="shading", albedo=True, uv=False, progress=None):
    """gbuffer(scene=None, camera=None, *, normal="shading", albedo=True, uv=False, progress=None) -> ao.GBuffer

    The G-buffer `ao render` renders for a scene and camera (docs/gbuffer.md): camera-space
    positions, unit normals, albedo, object ids, the camera. Pass it to render(gbuffer=...) to run
    several screen-space methods on one G-buffer.
    """
    request = {"camera": _camera_dict(camera), "normal": _check.text("normal", normal), "albedo": _check.flag("albedo", albedo),
               "uv": _check.flag("uv", uv)}
    return _run(_ao.gbuffer, progress, _scene_arg(scene), {k: v for k, v in request.items() if v is not None})


def gbuffer_from_arrays(normal, *, depth=None, position=None, albedo=None, object_id=None, camera):
    """gbuffer_from_arrays(normal, *, depth=None, position=None, albedo=None, object_id=None, camera)
       -> ao.GBuffer

    A G-buffer from another renderer's arrays, for the screen-space methods (render(gbuffer=...)).

    normal     H x W x 3 unit normals in camera space (x right, y up, looking down -z), facing
               the camera
    depth      H x W linear depth along -z (world units), or
    position   H x W x 3 camera-space positions (one of the two)
    albedo     H x W x 3, optional (0.8 grey)
    object_id  H x W unsigned ids, 0 = background, optional (covered where the depth is finite,
               > 0 and < 1e9)
    camera     the projection: an ao.Camera or dict with fov (vertical, degrees) and optionally its
               world placement; width and height, when given, must match the arrays
    """
    return _ao.GBuffer.from_arrays(normal, depth=depth, position=position, albedo=albedo, object_id=object_id,
                                   camera=_camera_dict(camera))


def bake(mesh, size=None, *, method="raytraced", uv_set=0, padding=None, map=True, per_vertex=False, seed=None,
         vertex_resolution=None, high=None, cage=None, cage_extrusion=None, max_front=None, max_back=None, cage_points=None,
         bent_normals=False, thickness=False, cavity=False, bent_normals_space=None, thickness_distance=None, cavity_distance=None,
         output=None, per_vertex_output=None, bent_normals_output=None, thickness_output=None, cavity_output=None, gltf_output=None,
         png_bits=None, provenance=False, full=False, progress=None, **params):
    """bake(mesh, size=None, *, method="raytraced", uv_set=0, padding=16, map=True, per_vertex=False,
         seed=1, high=None, cage=None, cage_extrusion=None, max_front=None, max_back=None,
         cage_points=4, bent_normals=False, thickness=False, cavity=False, bent_normals_space="world",
         thickness_distance=0.25, cavity_distance=0.02, output=None, per_vertex_output=None,
         bent_normals_output=None, thickness_output=None, cavity_output=None, gltf_output=None,
         png_bits=None, provenance=False, full=False, progress=None, **params)
       -> numpy.ndarray

    Bakes AO into a mesh's UV space as `ao bake` does (one mesh; a folder: python3 -m ao.batch).

    mesh        a mesh file with UVs, or an ao.Scene (Scene.from_arrays(..., uvs=...)); per-vertex
                AO (map=False, per_vertex=True) needs no UVs
    size        texels per side: N, "N" or "WIDTHxHEIGHT" (default 1024)
    method      "raytraced" (default) or "histogram"
    uv_set      the UV set to bake into (glTF TEXCOORD_n)
    padding     texels filled outside the charts (default 16); beyond them the map holds 0
    map         bake the map (H x W float32; row 0 is the top row of the image file)
    per_vertex  bake per-vertex AO (1-D float32, one value per vertex of the mesh as loaded)
    seed        seed of the sample sets (default 1)
    high        high to low (`ao bake --high`): the AO of these high-poly meshes (an ao.Scene, or a
                list of mesh files) baked into `mesh`'s UVs, rays from the cage inwards
    cage        an explicit cage (an ao.Scene or a mesh file with `mesh`'s topology, pushed out);
                or cage_extrusion: the low mesh pushed out along its smoothed normals, world
                units (default: fitted to the pair, docs/methods/bake.md); max_front, max_back, cage_points as
                `--max-front, --max-back, --cage-points`
    bent_normals, thickness, cavity
                also bake these maps of the AO family (ray-traced; docs/methods/bake.md): the
                average open direction (H x W x 3), the thickness (rays into the mesh) and the
                cavity (AO within a short distance), H x W float32 each; they come back in the
                dict that full=True returns, which bake then returns whatever `full` says
    bent_normals_space  "world" (default) or "tangent": MikkTSpace frames, as Blender and engines read them
    thickness_distance, cavity_distance
                R of the thickness and cavity maps, fractions of the baked mesh's bounding-box
                diagonal (default 0.25 and 0.02)
    output, per_vertex_output, bent_normals_output, thickness_output, cavity_output, gltf_output, png_bits
                files to write (mesh files only) as `ao bake -o, --per-vertex, --bent-normals,
                --thickness, --cavity, --gltf, --png-bits`
    provenance  also write each file's record beside it, FILE.ao.json (`--provenance`)
    full        return {"map", "mask" (1 where a texel is covered), "per_vertex", "bent_normals", "thickness",
                "cavity", "summary"} (those baked)
    progress    True (a bar) or a callable(stage, done, total) (module docstring)
    **params    the baker's parameters (`ao bake --help`): samples, denoise, max_distance,
                membership, texel_sampling, offset, normal, ignore_back_faces, spread_angle, relative_distance;
                histogram: directions, ...

    Returns the map; only per-vertex values when map=False; (map, per_vertex) when both.
    """
    map_ = _check.flag("map", map)
    per_vertex = _check.flag("per_vertex", per_vertex)
    request = _bake_request(size=size, method=method, uv_set=uv_set, padding=padding, vertex_resolution=vertex_resolution, seed=seed,
                            params=params, map=map_, per_vertex=per_vertex, output=output, per_vertex_output=per_vertex_output,
                            bent_normals_output=bent_normals_output, gltf_output=gltf_output, png_bits=png_bits, provenance=provenance,
                            thickness_output=thickness_output, cavity_output=cavity_output, bent_normals_space=bent_normals_space,
                            thickness_distance=thickness_distance, cavity_distance=cavity_distance)
    family = {"bent_normals": _check.flag("bent_normals", bent_normals), "thickness": _check.flag("thickness", thickness),
              "cavity": _check.flag("cavity", cavity)}
    request.update({k: v for k, v in family.items() if v})
    request.update({k: _check.number(k, v, optional=True) for k, v in
                    (("cage_extrusion", cage_extrusion), ("max_front", max_front), ("max_back", max_back)) if v is not None})
    if cage_points is not None:
        request["cage_points"] = _check.integer("cage_points", cage_points)
    high_to_low = _functools.partial(_ao.bake, high=_high_arg(high), cage=_cage_arg(cage))
    out = _run(high_to_low, progress, _mesh_arg(mesh), request)
    if _check.flag("full", full) or any(family.values()):
        return out
    if map_ and per_vertex:
        return out.get("map"), out.get("per_vertex")
    return out.get("map") if map_ else out.get("per_vertex")


def _mesh_arg(mesh):
    if isinstance(mesh, Scene):
        return mesh
    return _check.path("mesh", mesh, optional=False)


def _high_arg(high):
    """bake()'s high: None, an ao.Scene, a mesh file or a list of them."""
    if high is None or isinstance(high, Scene):
        return high
    if isinstance(high, (list, tuple)):
        return [_check.path(f"high[{k}]", h, optional=False) for k, h in enumerate(high)]
    return [_check.path("high", high, optional=False)]


def _cage_arg(cage):
    return cage if cage is None or isinstance(cage, Scene) else _check.path("cage", cage, optional=False)


def _bake_request(*, size, method, uv_set, padding, vertex_resolution, seed, params, map, per_vertex, output, per_vertex_output,
                  bent_normals_output, gltf_output, png_bits, provenance, thickness_output=None, cavity_output=None, bent_normals_space=None,
                  thickness_distance=None, cavity_distance=None):
    """The job layer's request for bake() (and ao.batch's records), every argument checked."""
    params = dict(params)
    if seed is not None:
        params["seed"] = _check.seed("seed", seed)
    if size is not None and not isinstance(size, str):
        size = _check.integer("size", size)
    request = {"method": _check.text("method", method), "size": size, "uv_set": _check.integer("uv_set", uv_set),
               "padding": _check.integer("padding", padding, optional=True),
               "vertex_resolution": _check.integer("vertex_resolution", vertex_resolution, optional=True), "params": params, "map": map,
               "per_vertex": per_vertex, "output": _check.path("output", output), "per_vertex_output": _check.path("per_vertex_output", per_vertex_output),
               "bent_normals_output": _check.path("bent_normals_output", bent_normals_output),
               "thickness_output": _check.path("thickness_output", thickness_output), "cavity_output": _check.path("cavity_output", cavity_output),
               "bent_normals_space": _check.text("bent_normals_space", bent_normals_space, optional=True),
               "thickness_distance": _check.number("thickness_distance", thickness_distance, optional=True),
               "cavity_distance": _check.number("cavity_distance", cavity_distance, optional=True),
               "gltf_output": _check.path("gltf_output", gltf_output), "png_bits": _check.integer("png_bits", png_bits, optional=True),
               "provenance": _check.flag("provenance", provenance)}
    return {k: v for k, v in request.items() if v is not None}


def occlusion(scene, points, normals, *, samples=256, radius=None, radius_fraction=None, membership=None, tau=None, target_error=None,
              offset=None, seed=1, full=False, progress=None):
    """occlusion(scene, points, normals, *, samples=256, radius=None, radius_fraction=None,
              membership=None, tau=None, target_error=None, offset=None, seed=1, full=False,
              progress=None) -> numpy.ndarray  (N float32: V per point)

    AO at points you choose (what libigl's ambient_occlusion gives), estimated as the ray-traced
    reference of `ao render` estimates each pixel: cosine-weighted directions about the normal,
    V = the mean of mu(D) over `samples` rays from the point, with its standard error.

    scene       a mesh file, a list of them, a built-in name or an ao.Scene
    points      N x 3 world-space points (on or just above the surface)
    normals     N x 3 normals, one per point (normalised; not zero)
    samples     rays per point, [1, 1048576]; the standard error falls as 1/sqrt(samples)
    radius, radius_fraction, membership, tau
                the falloff as for render(): R in world units (default 0.1 x the objects'
                diagonal), mu(d) step (default), linear, sqrt, cubic, exp
    target_error, offset, seed
                adaptive stop per point, ray origin offset (world units; 0: scale-free), and the
                seed: point i uses the sample set keyed by (seed, i)
    full        return {"visibility", "std_error", "summary"} instead

        >>> v = ao.occlusion("plane", [[0, 0, 0]], [[0, 1, 0]], samples=16)
        >>> float(v[0])   # nothing above an open plane
        1.0
    """
    params = {"samples": _check.integer("samples", samples)}
    if target_error is not None:
        params["target_error"] = _check.number("target_error", target_error)
    if offset is not None:
        params["offset"] = _check.number("offset", offset)
    request = {**_falloff(radius, radius_fraction, membership, tau), "params": params, "seed": _check.seed("seed", seed)}
    out = _run(_ao.occlusion, progress, _scene_arg(scene), points, normals, {k: v for k, v in request.items() if v is not None})
    return out if _check.flag("full", full) else out["visibility"]


def compare(scene=None, camera=None, methods=None, *, reference=None, common_reference=None, spp_reference=None, seed=1,
            radius=None, radius_fraction=None, membership=None, tau=None, normal="shading", params=None, sweep=None, out_dir=None,
            full=False, images=False, progress=None):
    """compare(scene=None, camera=None, methods=None, *, reference=None, common_reference="obscurance",
            spp_reference=256, seed=1,
            radius=None, radius_fraction=None, membership=None, tau=None, normal="shading",
            params=None, sweep=None, out_dir=None, full=False, images=False, progress=None) -> list of dict

    Compares methods with the ray-traced reference as `ao compare` does; one dict per method:
    {"method", "parameters", "reference" {kind, label, ...}, "rmse", "psnr_db", "ssim",
    "mean_signed_error", "max_abs_error", "ms", "pixels", "common" {rmse, psnr_db, ssim, ...},
    "stats"}.

    methods     registry names; None: every method but raytraced
    reference   the reference for every method ("matched", "obscurance", "tangent-sphere",
                "transfer"), or {method: reference}
    common_reference
                the one reference every row is also judged against ("common"), so that rows can
                be ranked: "obscurance" (of the requested falloff), "tangent-sphere", "transfer"
                or "none"
    params      {method: {parameter: value}} over each method's defaults
    sweep       {parameter: [values]}: one extra table of RMSE and time per value
    out_dir     also write table.json, table.md and sheet.png there (atomically)
    full        return {"table" (table.json's content), "markdown" (table.md)}
    images      with full: also "images", per row {"method", "visibility", "reference"} arrays
    camera      as for render; default 640 x 360
    progress    True (a bar) or a callable(stage, done, total) (module docstring)
    """
    if isinstance(methods, str):
        methods = [methods]
    if methods is not None and (not isinstance(methods, (list, tuple)) or not all(isinstance(m, str) for m in methods)):
        raise TypeError(f"methods: expected a list of method names, got {type(methods).__name__}")
    if params is not None and not isinstance(params, dict):
        raise TypeError(f"params: expected a dict {{method: {{parameter: value}}}}, got {type(params).__name__}")
    if sweep is not None and not isinstance(sweep, dict):
        raise TypeError(f"sweep: expected a dict {{parameter: [values]}}, got {type(sweep).__name__}")
    request = {"methods": methods, "reference": reference, "common_reference": _check.text("common_reference", common_reference, optional=True),
               "spp_reference": _check.integer("spp_reference", spp_reference, optional=True), "seed": _check.seed("seed", seed),
               **_falloff(radius, radius_fraction, membership, tau), "normal": _check.text("normal", normal), "params": params,
               "sweep": sweep, "out_dir": _check.path("out_dir", out_dir), "camera": _camera_dict(camera), "images": _check.flag("images", images)}
    out = _run(_ao.compare, progress, _scene_arg(scene), {k: v for k, v in request.items() if v is not None})
    return out if _check.flag("full", full) else out["table"]["rows"]


def _parameter_help():
    lines = ["", "Method parameters (**params; the same table as `ao render -p` and --json):"]
    for m in _ao.methods():
        lines.append("")
        lines.append(f"  {m['name']}: {m['summary']}")
        for p in m["params"]:
            lines.append(f"    {p['name']}={p['default']!r}  {p['help']} [{p['valid']}]")
    return "\n".join(lines)


render.__doc__ += _parameter_help()
