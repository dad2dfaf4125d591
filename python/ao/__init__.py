"""ao: ambient occlusion on the CPU, from Python (README "Python").

The calls stand on the C++ library's job layer (src/ao/jobs/), the same code `ao render`, `ao bake`
and `ao compare` run, so an array from here equals the CLI's output for the same inputs and seed.

    import ao
    v = ao.render("wedge", ao.Camera(width=320, height=180), method="volumetric")  # H x W float32
    m = ao.bake(ao.Scene.from_arrays(vertices, faces, uvs=uvs), size=256)        # the AO map
    rows = ao.compare("sphere-on-plane", methods=["alchemy", "gtao"])             # list of dicts

Values: V in [0, 1] per pixel or texel, 1 = fully open, 0 = fully occluded; 0 where nothing is
covered (background pixels, texels outside the charts; see `mask`).

Errors: a bad parameter value or a bad file raises ao.InputError (a ValueError subclass) with the
one line `ao` prints after "ao: error: "; an I/O failure (disk full, permissions) raises OSError;
Ctrl-C raises KeyboardInterrupt within a fraction of a second. The GIL is released while the job
computes, so other Python threads run meanwhile. Warnings of the job (e.g. degenerate triangles
dropped) are issued with warnings.warn.
"""

import os as _os

from . import _ao
from ._ao import GBuffer, InputError, Scene, read_image, __version__

__all__ = ["Camera", "GBuffer", "InputError", "Scene", "bake", "compare", "gbuffer", "gbuffer_from_arrays", "methods",
           "read_image", "render", "set_threads", "__version__"]


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
        self.eye, self.target, self.up, self.fov, self.width, self.height = eye, target, up, fov, width, height

    @classmethod
    def read(cls, path):
        """Camera.read(path) -> Camera: a camera JSON file (ao.InputError naming it when bad)."""
        return cls.from_dict(_ao.read_camera(_os.fspath(path)))

    @classmethod
    def from_dict(cls, d):
        """Camera.from_dict({"eye": [..], "target": [..], "up": [..], "fov": 45, "width": .., "height": ..})."""
        unknown = set(d) - set(cls._fields)
        if unknown:
            raise InputError("camera: unknown field(s) " + ", ".join(sorted(unknown)) + "; the fields are " + ", ".join(cls._fields))
        return cls(**d)

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
    raise InputError(f"camera: expected an ao.Camera, a dict or a camera JSON file, got {type(camera).__name__}")


def _scene_arg(scene):
    if isinstance(scene, _os.PathLike):
        return _os.fspath(scene)
    if isinstance(scene, (list, tuple)):
        return [_os.fspath(s) for s in scene]
    return scene


def _path(p):
    return None if p is None else _os.fspath(p)


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
    _ao.set_threads(threads)


def render(scene=None, camera=None, method="raytraced", *, gbuffer=None, spp=None, target_error=None, seed=1, radius=None,
           radius_fraction=None, membership=None, tau=None, normal=None, output=None, shaded=None, gbuffer_output=None,
           png_bits=8, extras=False, full=False, **params):
    """render(scene=None, camera=None, method="raytraced", *, gbuffer=None, spp=None, target_error=None,
           seed=1, radius=None, radius_fraction=None, membership=None, tau=None, normal=None,
           output=None, shaded=None, gbuffer_output=None, png_bits=8, extras=False, full=False,
           **params) -> numpy.ndarray  (H x W float32, V per pixel)

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
    full            return a dict instead: {"visibility", "std_error" (raytraced: the standard
                    error of V per pixel), "color" (RGB methods), "extras" {name: array},
                    "summary" (what `ao render --json` prints), "gbuffer" (ao.GBuffer)}
    **params        the method's parameters by name (`ao render -p key=value`), checked against its
                    table (listed below); a bad one raises ao.InputError (a ValueError)
    """
    request = {"method": method, "params": params, "samples": spp, "target_error": target_error, "seed": seed,
               "radius": radius, "radius_fraction": radius_fraction, "membership": membership, "tau": tau, "normal": normal,
               "camera": _camera_dict(camera), "output": _path(output), "shaded": _path(shaded),
               "gbuffer_output": _path(gbuffer_output), "png_bits": png_bits, "extras": extras, "return_gbuffer": full}
    out = _ao.render(_scene_arg(scene), gbuffer, {k: v for k, v in request.items() if v is not None})
    return out if full else out["visibility"]


def gbuffer(scene=None, camera=None, *, normal="shading", albedo=True, uv=False):
    """gbuffer(scene=None, camera=None, *, normal="shading", albedo=True, uv=False) -> ao.GBuffer

    The G-buffer `ao render` renders for a scene and camera (docs/gbuffer.md): camera-space
    positions, unit normals, albedo, object ids, the camera. Pass it to render(gbuffer=...) to run
    several screen-space methods on one G-buffer.
    """
    return _ao.gbuffer(_scene_arg(scene), {"camera": _camera_dict(camera), "normal": normal, "albedo": albedo, "uv": uv})


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
         vertex_resolution=None, output=None, per_vertex_output=None, bent_normals_output=None, gltf_output=None, png_bits=None,
         full=False, **params):
    """bake(mesh, size=None, *, method="raytraced", uv_set=0, padding=16, map=True, per_vertex=False,
         seed=1, output=None, per_vertex_output=None, bent_normals_output=None, gltf_output=None,
         png_bits=None, full=False, **params) -> numpy.ndarray

    Bakes AO into a mesh's UV space as `ao bake` does (one mesh; a folder: python3 -m ao.batch).

    mesh        a mesh file with UVs, or an ao.Scene (Scene.from_arrays(..., uvs=...))
    size        texels per side: N, "N" or "WIDTHxHEIGHT" (default 1024)
    method      "raytraced" (default) or "histogram"
    uv_set      the UV set to bake into (glTF TEXCOORD_n)
    padding     texels filled outside the charts (default 16)
    map         bake the map (H x W float32; row 0 is the top row of the image file)
    per_vertex  bake per-vertex AO (1-D float32, one value per vertex of the mesh as loaded)
    seed        seed of the sample sets (default 1)
    output, per_vertex_output, bent_normals_output, gltf_output, png_bits
                files to write (mesh files only) as `ao bake -o, --per-vertex, --bent-normals,
                --gltf, --png-bits`
    full        return {"map", "mask" (1 where a texel is covered), "per_vertex", "summary"}
    **params    the baker's parameters (`ao bake --help`): samples, denoise, max_distance,
                membership, offset, normal, ignore_back_faces; histogram: directions, ...

    Returns the map; only per-vertex values when map=False; (map, per_vertex) when both.
    """
    if seed is not None:
        params["seed"] = seed
    request = {"method": method, "size": size, "uv_set": uv_set, "padding": padding, "vertex_resolution": vertex_resolution,
               "params": params, "map": map, "per_vertex": per_vertex, "output": _path(output),
               "per_vertex_output": _path(per_vertex_output), "bent_normals_output": _path(bent_normals_output),
               "gltf_output": _path(gltf_output), "png_bits": png_bits}
    out = _ao.bake(_scene_arg(mesh), {k: v for k, v in request.items() if v is not None})
    if full:
        return out
    if map and per_vertex:
        return out.get("map"), out.get("per_vertex")
    return out.get("map") if map else out.get("per_vertex")


def compare(scene=None, camera=None, methods=None, *, reference=None, common_reference=None, spp_reference=None, seed=1,
            radius=None, radius_fraction=None, membership=None, tau=None, normal="shading", params=None, sweep=None, out_dir=None,
            full=False, images=False):
    """compare(scene=None, camera=None, methods=None, *, reference=None, common_reference="obscurance",
            spp_reference=256, seed=1,
            radius=None, radius_fraction=None, membership=None, tau=None, normal="shading",
            params=None, sweep=None, out_dir=None, full=False, images=False) -> list of dict

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
    """
    request = {"methods": methods, "reference": reference, "common_reference": common_reference, "spp_reference": spp_reference,
               "seed": seed, "radius": radius,
               "radius_fraction": radius_fraction, "membership": membership, "tau": tau, "normal": normal, "params": params,
               "sweep": sweep, "out_dir": _path(out_dir), "camera": _camera_dict(camera), "images": images}
    out = _ao.compare(_scene_arg(scene), {k: v for k, v in request.items() if v is not None})
    return out if full else out["table"]["rows"]


def _parameter_help():
    lines = ["", "Method parameters (**params; the same table as `ao render -p` and --json):"]
    for m in _ao.methods():
        lines.append("")
        lines.append(f"  {m['name']}: {m['summary']}")
        for p in m["params"]:
            lines.append(f"    {p['name']}={p['default']!r}  {p['help']} [{p['valid']}]")
    return "\n".join(lines)


render.__doc__ += _parameter_help()
