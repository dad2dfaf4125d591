# SPDX-License-Identifier: Apache-2.0
"""Blender's mesh data as the arrays of ao.Scene.from_arrays, and ao's maps as Blender's pixels.

Used by the Blender add-on (ao/_blender_addon.py); needs numpy only, so it takes Blender's mesh
through the few attributes it reads. A Blender mesh keeps positions per vertex but UVs and shading
normals per loop (a corner of a polygon); ao keeps all three per vertex. Each corner of Blender's
loop triangles becomes a vertex, and corners with equal position, UV and normal are welded into
one, numbered in the order the triangles first use them: what ao's OBJ reader makes of an OBJ that
lists the same corners (src/ao/io/obj_reader.h), so a mesh baked from Blender and the same mesh
baked from such a file get the same vertices, triangles and bits.
"""

import numpy as np


def _read(collection, attribute, count, width, dtype):
    """`attribute` of every item of a Blender collection through foreach_get: count x width."""
    values = np.empty(count * width, dtype)
    collection.foreach_get(attribute, values)
    return values.reshape(count, width) if width > 1 else values


def uv_layer(mesh, name=""):
    """The UV map called `name`, or the active one (the one Blender's own bake uses) when ""; None when
    the mesh has none or none of that name."""
    if name:
        return mesh.uv_layers.get(name)
    return mesh.uv_layers.active


def corners(mesh, matrix_world, uv_name=""):
    """The corners of `mesh`'s loop triangles in world space, in triangle order: (positions T*3 x 3,
    normals T*3 x 3, uvs T*3 x 2 or None, Blender vertex index per corner).

    `mesh` must have had calc_loop_triangles() and calc_normals_split() called. Normals are
    Blender's loop normals (flat, smooth, auto-smooth or custom: what the viewport shades with),
    taken through the inverse transpose of the matrix and left for ao to normalise; positions and
    normals are computed in double and rounded to float once."""
    loops = _read(mesh.loop_triangles, "loops", len(mesh.loop_triangles), 3, np.int32).ravel()
    vertex_of_loop = _read(mesh.loops, "vertex_index", len(mesh.loops), 1, np.int32)
    positions = _read(mesh.vertices, "co", len(mesh.vertices), 3, np.float32)
    normals = _read(mesh.loops, "normal", len(mesh.loops), 3, np.float32)
    layer = uv_layer(mesh, uv_name)
    uvs = _read(layer.data, "uv", len(mesh.loops), 2, np.float32)[loops] if layer is not None else None
    m = np.array(matrix_world, dtype=np.float64).reshape(4, 4)
    linear = m[:3, :3]
    if np.linalg.det(linear) < 0:  # a mirroring matrix turns the triangles over: keep them counter-clockwise
        loops = loops.reshape(-1, 3)[:, ::-1].ravel()
        uvs = uvs.reshape(-1, 3, 2)[:, ::-1].reshape(-1, 2) if uvs is not None else None
    vertices = vertex_of_loop[loops]
    world = (positions[vertices].astype(np.float64) @ linear.T + m[:3, 3]).astype(np.float32)
    world_normals = (normals[loops].astype(np.float64) @ np.linalg.inv(linear)).astype(np.float32)  # n^T M^-1 = (M^-T n)^T
    return world, world_normals, uvs, vertices


def weld(positions, normals, uvs):
    """Corners with equal position, normal and UV (-0 equal to +0) welded, numbered by first use:
    (vertices, normals, uvs or None, faces M x 3, the first corner of each vertex)."""
    columns = [positions, normals] + ([uvs] if uvs is not None else [])
    keys = np.ascontiguousarray(np.hstack(columns) + np.float32(0))  # + 0 turns -0 into +0
    keys = keys.view(np.dtype((np.void, keys.dtype.itemsize * keys.shape[1]))).ravel()
    _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    order = np.argsort(first, kind="stable")  # unique values by their first corner
    number = np.empty(len(order), np.int64)
    number[order] = np.arange(len(order))
    corner = first[order]
    faces = number[inverse.ravel()].reshape(-1, 3)
    return positions[corner], normals[corner], (uvs[corner] if uvs is not None else None), faces, corner


def map_to_pixels(visibility):
    """ao's map (H x W, row 0 the top of the image) as Blender's RGBA float pixels (rows from the
    bottom), V in red, green and blue and 1 in alpha, flattened for Image.pixels.foreach_set."""
    v = np.flipud(np.asarray(visibility, dtype=np.float32))
    rgba = np.empty(v.shape + (4,), np.float32)
    rgba[..., :3] = v[..., None]
    rgba[..., 3] = 1.0
    return rgba.ravel()


def vectors_to_pixels(vectors):
    """Bent normals (H x W x 3, row 0 on top) as Blender's RGBA float pixels: n * 0.5 + 0.5 in RGB
    (0.5 where there is no direction), as `ao bake --bent-normals` writes them; 1 in alpha."""
    n = np.flipud(np.asarray(vectors, dtype=np.float32))
    rgba = np.ones(n.shape[:2] + (4,), np.float32)
    empty = ~np.any(n != 0, axis=-1)
    rgba[..., :3] = n * np.float32(0.5) + np.float32(0.5)
    rgba[empty, :3] = 0.5
    return rgba.ravel()


def pixels_to_map(pixels, width, height):
    """The inverse of map_to_pixels: the red channel of Blender's pixels as an H x W map, row 0 on top."""
    return np.flipud(np.asarray(pixels, dtype=np.float32).reshape(height, width, 4)[..., 0]).copy()
