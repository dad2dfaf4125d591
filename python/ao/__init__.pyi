# SPDX-License-Identifier: Apache-2.0
# Type stubs of the package ao (python/ao/__init__.py), installed with it (PEP 561: py.typed).
# Checked against the module by tests/python/test_stubs.py (mypy's stubtest).
import os
from typing import Any, Callable, Literal, Mapping, Optional, Sequence, Union, overload

import numpy as np
import numpy.typing as npt

from ._ao import GBuffer as GBuffer, InputError as InputError, Scene as Scene, __version__ as __version__, read_image as read_image

__all__ = ["Camera", "GBuffer", "InputError", "Scene", "bake", "compare", "gbuffer", "gbuffer_from_arrays", "methods", "occlusion",
           "read_image", "render", "set_threads", "__version__"]

_PathLike = Union[str, os.PathLike[str]]
_Vector3 = Union[Sequence[float], npt.NDArray[Any]]
_SceneArg = Union[None, str, os.PathLike[str], Sequence[_PathLike], Scene]
_CameraArg = Union[None, "Camera", Mapping[str, Any], str, os.PathLike[str]]
_Progress = Union[None, bool, Callable[[str, int, int], object]]
_FloatArray = npt.NDArray[np.float32]

class Camera:
    eye: Optional[list[float]]
    target: Optional[list[float]]
    up: Optional[list[float]]
    fov: Optional[float]
    width: Optional[int]
    height: Optional[int]
    def __init__(self, eye: Optional[_Vector3] = ..., target: Optional[_Vector3] = ..., up: Optional[_Vector3] = ..., fov: Optional[float] = ...,
                 width: Optional[int] = ..., height: Optional[int] = ...) -> None: ...
    @classmethod
    def read(cls, path: _PathLike) -> Camera: ...
    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Camera: ...
    def to_dict(self) -> dict[str, Any]: ...
    def write(self, path: _PathLike) -> None: ...
    def __eq__(self, other: object) -> bool: ...

def methods() -> list[dict[str, Any]]: ...
def set_threads(threads: int) -> None: ...
@overload
def render(scene: _SceneArg = ..., camera: _CameraArg = ..., method: str = ..., *, gbuffer: Optional[GBuffer] = ..., spp: Optional[int] = ...,
           target_error: Optional[float] = ..., seed: int = ..., radius: Optional[float] = ..., radius_fraction: Optional[float] = ...,
           membership: Optional[str] = ..., tau: Optional[float] = ..., normal: Optional[str] = ..., output: Optional[_PathLike] = ...,
           shaded: Optional[_PathLike] = ..., gbuffer_output: Optional[_PathLike] = ..., png_bits: int = ..., extras: bool = ...,
           provenance: bool = ..., full: Literal[False] = ..., progress: _Progress = ..., **params: Any) -> _FloatArray: ...
@overload
def render(scene: _SceneArg = ..., camera: _CameraArg = ..., method: str = ..., *, gbuffer: Optional[GBuffer] = ..., spp: Optional[int] = ...,
           target_error: Optional[float] = ..., seed: int = ..., radius: Optional[float] = ..., radius_fraction: Optional[float] = ...,
           membership: Optional[str] = ..., tau: Optional[float] = ..., normal: Optional[str] = ..., output: Optional[_PathLike] = ...,
           shaded: Optional[_PathLike] = ..., gbuffer_output: Optional[_PathLike] = ..., png_bits: int = ..., extras: bool = ...,
           provenance: bool = ..., full: Literal[True], progress: _Progress = ..., **params: Any) -> dict[str, Any]: ...
def gbuffer(scene: _SceneArg = ..., camera: _CameraArg = ..., *, normal: str = ..., albedo: bool = ..., uv: bool = ...,
            progress: _Progress = ...) -> GBuffer: ...
def gbuffer_from_arrays(normal: npt.ArrayLike, *, depth: Optional[npt.ArrayLike] = ..., position: Optional[npt.ArrayLike] = ...,
                        albedo: Optional[npt.ArrayLike] = ..., object_id: Optional[npt.ArrayLike] = ...,
                        camera: Union[Camera, Mapping[str, Any]]) -> GBuffer: ...
def bake(mesh: Union[_PathLike, Scene], size: Union[None, int, str] = ..., *, method: str = ..., uv_set: int = ..., padding: Optional[int] = ...,
         map: bool = ..., per_vertex: bool = ..., seed: Optional[int] = ..., vertex_resolution: Optional[int] = ...,
         high: Union[None, Scene, _PathLike, Sequence[_PathLike]] = ..., cage: Union[None, Scene, _PathLike] = ...,
         cage_extrusion: Optional[float] = ..., max_front: Optional[float] = ..., max_back: Optional[float] = ...,
         cage_points: Optional[int] = ..., bent_normals: bool = ..., thickness: bool = ..., cavity: bool = ...,
         bent_normals_space: Optional[str] = ..., thickness_distance: Optional[float] = ..., cavity_distance: Optional[float] = ...,
         output: Optional[_PathLike] = ..., per_vertex_output: Optional[_PathLike] = ..., bent_normals_output: Optional[_PathLike] = ...,
         thickness_output: Optional[_PathLike] = ..., cavity_output: Optional[_PathLike] = ...,
         gltf_output: Optional[_PathLike] = ..., png_bits: Optional[int] = ..., provenance: bool = ..., full: bool = ...,
         progress: _Progress = ..., **params: Any) -> Any: ...
@overload
def occlusion(scene: _SceneArg, points: npt.ArrayLike, normals: npt.ArrayLike, *, samples: int = ..., radius: Optional[float] = ...,
              radius_fraction: Optional[float] = ..., membership: Optional[str] = ..., tau: Optional[float] = ...,
              target_error: Optional[float] = ..., offset: Optional[float] = ..., seed: int = ..., full: Literal[False] = ...,
              progress: _Progress = ...) -> _FloatArray: ...
@overload
def occlusion(scene: _SceneArg, points: npt.ArrayLike, normals: npt.ArrayLike, *, samples: int = ..., radius: Optional[float] = ...,
              radius_fraction: Optional[float] = ..., membership: Optional[str] = ..., tau: Optional[float] = ...,
              target_error: Optional[float] = ..., offset: Optional[float] = ..., seed: int = ..., full: Literal[True],
              progress: _Progress = ...) -> dict[str, Any]: ...
def compare(scene: _SceneArg = ..., camera: _CameraArg = ..., methods: Union[None, str, Sequence[str]] = ..., *,
            reference: Union[None, str, Mapping[str, str]] = ..., common_reference: Optional[str] = ..., spp_reference: Optional[int] = ...,
            seed: int = ..., radius: Optional[float] = ..., radius_fraction: Optional[float] = ..., membership: Optional[str] = ...,
            tau: Optional[float] = ..., normal: str = ..., params: Optional[Mapping[str, Mapping[str, Any]]] = ...,
            sweep: Optional[Mapping[str, Sequence[Any]]] = ..., out_dir: Optional[_PathLike] = ..., full: bool = ..., images: bool = ...,
            progress: _Progress = ...) -> Any: ...
