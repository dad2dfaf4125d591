"""Batch work on a Dask cluster: one task per mesh, view or frame (README "Cluster", docs/cluster.md).

    python3 -m ao.batch bake DIR --out-dir OUT [--size N] [-p key=value ...] (--scheduler ADDR | --local N)
    python3 -m ao.batch render VIEWS.json --out-dir OUT ...
    python3 -m ao.batch compare DIR --out-dir OUT ...

Each task writes its output through the library's atomic writers (a hidden temporary file beside
the output, renamed into place when complete), so an output that exists under its final name is
complete: the rename is the commit. A rerun skips every task whose output exists, before
submitting anything. A worker lost mid-task (killed, its machine gone) has its task rerun on
another worker by the scheduler; the rerun first removes the temporary files the lost worker left
for that output (the scheduler runs a task on one worker at a time). A task that fails for bad
input returns its one-line reason instead of raising, so it is reported once and never retried.
Exit code 0 when every task is done or skipped, 1 when any failed, 2 for bad usage.
"""

import argparse
import hashlib
import json
import os
import sys
import time

MESH_EXTENSIONS = (".obj", ".ply", ".off", ".stl", ".gltf", ".glb")


def _value(text):
    try:
        return json.loads(text)
    except ValueError:
        return text


def _params(pairs):
    params = {}
    for pair in pairs or []:
        key, sep, value = pair.partition("=")
        if not sep or not key:
            raise SystemExit(f"ao.batch: error: -p {pair}: expected key=value")
        params[key] = _value(value)
    return params


# ---- The tasks, run on the workers. Each returns {"status": "done" | "skipped" | "failed", ...}.

def _task(out, threads, work):
    """Runs `work()`, which writes `out`, unless `out` exists; bad input becomes a failed result."""
    import ao
    if os.path.exists(out):
        return {"status": "skipped", "output": out}
    ao._ao.remove_abandoned_temporaries(out)
    ao.set_threads(threads)
    started = time.monotonic()
    try:
        work()
    except ao.InputError as e:
        return {"status": "failed", "reason": str(e)}
    return {"status": "done", "output": out, "seconds": time.monotonic() - started}


def bake_task(mesh, out, options, threads):
    """Bakes `mesh`'s AO map to `out` (ao.bake with `options`)."""
    import ao
    return _task(out, threads, lambda: ao.bake(mesh, output=out, **options))


def render_task(view, out, threads):
    """Renders one view (a dict of ao.render's arguments: scene, camera, method, parameters) to `out`."""
    import ao
    kwargs = {k: v for k, v in view.items() if k not in ("scene", "camera", "output")}
    return _task(out, threads, lambda: ao.render(view.get("scene"), view.get("camera"), output=out, **kwargs))


def compare_task(mesh, out, options, threads):
    """Compares the methods on `mesh` (ao.compare with `options`); its rows go to `out` (JSON)."""
    import ao

    def work():
        rows = ao.compare(mesh, **options)
        ao._ao.write_text(out, json.dumps({"mesh": os.path.basename(mesh), "rows": rows}, indent=1) + "\n")
    return _task(out, threads, work)


# ---- The client: the task list, the cluster, progress and summary.

def _meshes(folder):
    if not os.path.isdir(folder):
        raise SystemExit(f"ao.batch: error: {folder}: not a folder of meshes")
    names = sorted(n for n in os.listdir(folder) if n.lower().endswith(MESH_EXTENSIONS) and not n.startswith("."))
    if not names:
        raise SystemExit(f"ao.batch: error: {folder}: no mesh files ({', '.join(MESH_EXTENSIONS)})")
    return [os.path.join(folder, n) for n in names]


def _unique_outputs(tasks):
    seen = {}
    for name, out, _, _ in tasks:
        if out in seen:
            raise SystemExit(f"ao.batch: error: {seen[out]} and {name} would both write {out}; rename one")
        seen[out] = name


def _key(kind, name, args):
    token = hashlib.sha1(json.dumps([kind, name, repr(args)]).encode()).hexdigest()[:12]
    return f"ao-{kind}-{os.path.basename(name)}-{token}"


def _mesh_tasks(args, suffix, fn, options):
    """One task per mesh of the input folder, writing OUT/<stem><suffix>."""
    tasks = []
    for mesh in _meshes(args.input):
        out = os.path.join(args.out_dir, os.path.splitext(os.path.basename(mesh))[0] + suffix)
        tasks.append((os.path.basename(mesh), out, fn, (mesh, out, options)))
    return tasks


def bake_tasks(args):
    return _mesh_tasks(args, f"-ao.{args.format}", bake_task, {"size": args.size, "seed": args.seed, **_params(args.param)})


def _turntable(spec, frames):
    import math
    eye, target = spec["camera"]["eye"], spec["camera"].get("target", [0, 0, 0])
    dx, dz = eye[0] - target[0], eye[2] - target[2]
    r, a0 = math.hypot(dx, dz), math.atan2(dz, dx)
    views = []
    for k in range(frames):
        a = a0 + 2 * math.pi * k / frames
        cam = dict(spec["camera"], eye=[target[0] + r * math.cos(a), eye[1], target[2] + r * math.sin(a)], target=target)
        views.append(dict(spec, camera=cam, output=f"{spec.get('output', 'frame')}-{k:04d}.{spec.get('format', 'exr')}"))
    return views


def render_tasks(args):
    try:
        with open(args.input, encoding="utf-8") as f:
            spec = json.load(f)
    except (OSError, ValueError) as e:
        raise SystemExit(f"ao.batch: error: {args.input}: {e}")
    if isinstance(spec, dict) and "turntable" in spec:
        frames = spec.pop("turntable")
        if "camera" not in spec or "eye" not in spec["camera"]:
            raise SystemExit(f"ao.batch: error: {args.input}: a turntable needs camera.eye (it circles camera.target about y)")
        views = _turntable(spec, frames)
    elif isinstance(spec, list):
        views = spec
    else:
        raise SystemExit(f"ao.batch: error: {args.input}: expected a list of views or {{\"turntable\": N, \"scene\": ..., \"camera\": ...}}")
    tasks = []
    for k, view in enumerate(views):
        view = dict(view)
        for key in ("format",):
            view.pop(key, None)
        if "output" not in view:
            raise SystemExit(f"ao.batch: error: {args.input}: view {k} names no output")
        out = os.path.join(args.out_dir, view["output"])
        tasks.append((view["output"], out, render_task, (view, out)))
    return tasks


def compare_tasks(args):
    methods = args.methods.split(",") if args.methods else None
    return _mesh_tasks(args, "-compare.json", compare_task, {"methods": methods, "spp_reference": args.spp_reference, "seed": args.seed})


def _client(args):
    from distributed import Client, LocalCluster
    if args.scheduler:
        return Client(args.scheduler, timeout="30s"), None
    cluster = LocalCluster(n_workers=args.local, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None)
    return Client(cluster), cluster


def run(tasks, args, out=sys.stdout):
    """Submits the tasks whose outputs are missing, prints a line per finished task and a summary;
    returns the exit code."""
    _unique_outputs(tasks)
    os.makedirs(args.out_dir, exist_ok=True)
    todo = [t for t in tasks if not os.path.exists(t[1])]
    skipped = len(tasks) - len(todo)
    done, failed = 0, []
    if todo:
        from distributed import as_completed
        client, cluster = _client(args)
        try:
            futures = {client.submit(fn, *fn_args, args.threads, key=_key(fn.__name__, name, fn_args), pure=False, retries=0): name
                       for name, _, fn, fn_args in todo}
            for k, future in enumerate(as_completed(futures), 1):
                name = futures[future]
                try:
                    result = future.result()
                except Exception as e:  # a system failure on the worker (OSError): reported, not retried
                    result = {"status": "failed", "reason": f"{type(e).__name__}: {e}"}
                status = result["status"]
                if status == "done":
                    done += 1
                    print(f"[{k}/{len(todo)}] done {name} -> {result['output']} ({result['seconds']:.2f} s)", file=out, flush=True)
                elif status == "skipped":
                    skipped += 1
                    print(f"[{k}/{len(todo)}] skipped {name}: {result['output']} exists", file=out, flush=True)
                else:
                    failed.append((name, result["reason"]))
                    print(f"[{k}/{len(todo)}] failed {name}: {result['reason']}", file=out, flush=True)
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    print(f"done {done}, failed {len(failed)}, skipped {skipped} (already present)", file=out, flush=True)
    for name, reason in failed:
        print(f"  failed {name}: {reason}", file=out, flush=True)
    return 1 if failed else 0


def parser():
    p = argparse.ArgumentParser(prog="python3 -m ao.batch", description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="command", required=True)

    def common(q):
        q.add_argument("--out-dir", required=True, help="shared output folder (created when missing)")
        where = q.add_mutually_exclusive_group(required=True)
        where.add_argument("--scheduler", metavar="tcp://HOST:PORT", help="an existing Dask scheduler")
        where.add_argument("--local", type=int, metavar="N", help="start N local workers of one task each")
        q.add_argument("--threads", type=int, default=0, help="ao's threads per task; 0 = all cores of the worker (default)")
        q.add_argument("--seed", type=int, default=1, help="seed of the sample sets (default 1)")

    b = sub.add_parser("bake", help="bake every mesh of a folder: OUT/<stem>-ao.<format>")
    b.add_argument("input", metavar="DIR")
    b.add_argument("--size", default="1024", help="map size: N or WIDTHxHEIGHT (default 1024)")
    b.add_argument("--format", default="png", choices=["png", "exr", "tif"], help="map format (default png, 8 bit)")
    b.add_argument("-p", "--param", action="append", metavar="KEY=VALUE", help="a baker parameter (ao bake --help), repeatable")
    common(b)
    r = sub.add_parser("render", help="render the views of a JSON file: OUT/<output>")
    r.add_argument("input", metavar="VIEWS.json",
                   help='[{"scene", "camera": {...}, "method", "output", parameters...}, ...] or '
                        '{"turntable": N, "scene", "camera": {"eye", "target", ...}, "output": "stem", "format": "exr"}')
    common(r)
    c = sub.add_parser("compare", help="compare methods on every mesh of a folder: OUT/table.json")
    c.add_argument("input", metavar="DIR")
    c.add_argument("--methods", help="comma-separated methods (default: every method but raytraced)")
    c.add_argument("--spp-reference", type=int, default=256, help="rays per pixel of the references (default 256)")
    common(c)
    return p


def _compare_table(args, tasks):
    import ao
    rows = []
    for _, out, _, _ in tasks:
        if os.path.exists(out):
            with open(out, encoding="utf-8") as f:
                part = json.load(f)
            rows += [dict(row, mesh=part["mesh"]) for row in part["rows"]]
    ao._ao.write_text(os.path.join(args.out_dir, "table.json"), json.dumps({"rows": rows}, indent=1) + "\n")


def main(argv=None):
    args = parser().parse_args(argv)
    if args.local is not None and args.local < 1:
        raise SystemExit("ao.batch: error: --local: expected at least 1 worker")
    tasks = {"bake": bake_tasks, "render": render_tasks, "compare": compare_tasks}[args.command](args)
    code = run(tasks, args)
    if args.command == "compare":
        _compare_table(args, tasks)
    return code


if __name__ == "__main__":
    sys.exit(main())
