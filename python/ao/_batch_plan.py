# SPDX-License-Identifier: Apache-2.0
"""What an ao.batch run will do, decided on the client before any task is submitted: the inputs
(folders, optionally recursive, and list files), every task with its outputs under --out-dir,
every argument checked by the library as the tasks will use it (a bad one is one line, exit 2,
nothing submitted), and each task's state against the outputs already there (ao/_batch_records.py).
"""

import os

from . import _batch_records as records

MESH_EXTENSIONS = (".obj", ".ply", ".off", ".stl", ".gltf", ".glb")


class Refused(Exception):
    """A bad argument or output, found before anything is submitted: one line, exit 2."""


# ---- Inputs

def _mesh_files(folder, recursive):
    """(path, path relative to `folder`) of the mesh files in `folder`, sorted; hidden ones left out."""
    found = []
    for root, dirs, files in os.walk(folder):
        dirs[:] = sorted(d for d in dirs if not d.startswith(".")) if recursive else []
        for name in sorted(files):
            if name.lower().endswith(MESH_EXTENSIONS) and not name.startswith("."):
                path = os.path.join(root, name)
                found.append((path, os.path.relpath(path, folder)))
    return found


def _list_file(path):
    """The mesh files a list file names, one per line ('#' starts a comment; relative paths are
    relative to the list file's folder)."""
    try:
        with open(path, encoding="utf-8") as f:
            lines = f.read().splitlines()
    except (OSError, UnicodeDecodeError) as e:
        raise Refused(f"{path}: cannot read the list of inputs: {getattr(e, 'strerror', None) or e}")
    base = os.path.dirname(os.path.abspath(path))
    out = []
    for number, line in enumerate(lines, 1):
        line = line.split("#", 1)[0].strip()
        if line:
            out.append((os.path.join(base, line), number))
    return out


def meshes(inputs, list_files, recursive):
    """[(absolute path, output stem)]: each mesh once. A folder's meshes keep their sub-folders in
    the stem (a/b/cow.obj -> a/b/cow), so outputs of a recursive walk do not collide; a file named
    directly or in a list file is known by its name alone."""
    found = []
    for given in inputs or []:
        if os.path.isdir(given):
            files = _mesh_files(given, recursive)
            if not files:
                raise Refused(f"{given}: no mesh files ({', '.join(MESH_EXTENSIONS)})" + ("" if recursive else "; --recursive searches sub-folders"))
            found += [(os.path.abspath(p), os.path.splitext(rel)[0]) for p, rel in files]
        elif os.path.isfile(given):
            found.append((os.path.abspath(given), os.path.splitext(os.path.basename(given))[0]))
        else:
            raise Refused(f"{given}: no such file or folder")
    for path in list_files or []:
        for mesh, line in _list_file(path):
            if not os.path.isfile(mesh):
                raise Refused(f"{path}:{line}: {mesh}: no such file")
            found.append((os.path.abspath(mesh), os.path.splitext(os.path.basename(mesh))[0]))
    if not found:
        raise Refused("no inputs: name mesh files, folders or --list FILE")
    seen, unique = set(), []
    for path, stem in found:
        if path not in seen:
            seen.add(path)
            unique.append((path, stem))
    return unique


# ---- Outputs

def confined(out_dir, name, what):
    """OUT_DIR/name for a name a views file gives: relative, no '..', inside --out-dir also after
    resolving symbolic links; Refused otherwise."""
    if not isinstance(name, str) or not name:
        raise Refused(f"{what}: expected a file name, got {name!r}")
    if os.path.isabs(name) or ".." in name.replace("\\", "/").split("/"):
        raise Refused(f"{what}: '{name}' leaves --out-dir; give a name relative to it, without '..'")
    path = os.path.join(out_dir, name)
    real_dir = os.path.realpath(out_dir)
    if os.path.commonpath([real_dir, os.path.realpath(path)]) != real_dir:
        raise Refused(f"{what}: '{name}' leads out of --out-dir through a symbolic link")
    return path


def check_out_dir(out_dir):
    """--out-dir, created when missing; Refused when it cannot be, or cannot be written."""
    try:
        os.makedirs(out_dir, exist_ok=True)
    except OSError as e:
        raise Refused(f"--out-dir {out_dir}: cannot create the folder: {e.strerror}")
    if not os.access(out_dir, os.W_OK | os.X_OK):
        raise Refused(f"--out-dir {out_dir}: the folder is not writable")


def unique_outputs(tasks):
    seen = {}
    for task in tasks:
        for out in task["outputs"]:
            if out in seen:
                raise Refused(f"{seen[out]} and {task['name']} would both write {out}; rename one")
            seen[out] = task["name"]


# ---- State of the outputs already there

def classify(tasks, force, verify):
    """Splits `tasks` into (todo, skipped, redo); Refused for an output name held by something that
    is not a file, or, without --force, for outputs made with other inputs or settings."""
    todo, skipped, redo, changed, blocked = [], [], [], [], []
    for task in tasks:
        outs = task["outputs"]
        if all(records.output_state(o) == "missing" for o in outs):
            todo.append(task)
            continue
        previous = records.read(records.record_path(outs[0]))
        state, why = records.made(outs, records.hash_inputs(task["record"], previous, verify))
        if state == "done":
            skipped.append(task)
        elif state == "missing":
            todo.append(task)
        elif state == "blocked":
            blocked += why
        else:
            changed.append((task, why))
    if blocked:
        more = f" (and {len(blocked) - 1} more)" if len(blocked) > 1 else ""
        raise Refused(f"{blocked[0]}, not an output file{more}; remove it or choose another --out-dir")
    if changed and not force:
        task, why = changed[0]
        more = f"; {len(changed) - 1} more outputs too" if len(changed) > 1 else ""
        raise Refused(f"{os.path.basename(task['outputs'][0])} was made otherwise ({', '.join(why[:4])}){more}: "
                      "rerun with --force to make them again, or choose another --out-dir")
    redo = [task for task, _ in changed]
    return todo + redo, skipped, redo
