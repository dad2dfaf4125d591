# SPDX-License-Identifier: Apache-2.0
"""Batch work on a Dask cluster: one task per mesh, view or frame (README "Cluster", docs/cluster.md).

    python3 -m ao.batch bake INPUT... --out-dir OUT [--size N] [--per-vertex ply] [-p key=value ...] (--scheduler ADDR | --local N)
    python3 -m ao.batch render VIEWS.json --out-dir OUT ...
    python3 -m ao.batch compare INPUT... --out-dir OUT ...

Before anything is submitted the client checks every argument as the library will use it, the
output folder, and every worker (ao importable, the client's version); a bad one is one line and
exit 2 (3 for the cluster), with nothing submitted. Each output is written with its provenance
record, OUTPUT.ao.json (ao's version, the inputs' SHA-256, every setting), by the library's
atomic writers: hidden temporary files beside them, renamed into place, the record last. A rerun
skips the outputs made from the same inputs and settings, refuses (one line naming what changed)
those made otherwise unless --force, and makes the missing ones. A worker lost mid-task has its
task rerun by the scheduler elsewhere; a system failure (OSError) is retried --retries times; bad
input is reported once and never retried. Exit code 0 when every task is done or skipped, 1 when
any failed, 2 for a bad argument or output, 3 when the cluster cannot run ao, 130 on Ctrl-C.
"""

import argparse
import logging
import os
import sys

from ._batch_plan import Refused, check_out_dir, classify, unique_outputs


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
        q.add_argument("--force", action="store_true", help="make again the outputs made with other inputs, settings or ao version")
        q.add_argument("--verify", action="store_true", help="hash every input again (default: only those whose size or time changed)")
        q.add_argument("--retries", type=int, default=2, help="times a task is retried after a system failure, not bad input (default 2)")
        q.add_argument("--log-dir", metavar="DIR", help="a log per task, DIR/<name>.log: its worker, progress, warnings and result")
        q.add_argument("--progress-file", metavar="FILE", help="progress as JSON, rewritten every second: counts, running tasks, time left")
        q.add_argument("--status-seconds", type=float, default=30.0, help="seconds between status lines (default 30)")
        q.add_argument("--progress-seconds", type=float, default=2.0, help="seconds between a task's progress events (default 2)")
        q.add_argument("--connect-timeout", type=float, default=5.0, help="seconds to reach the scheduler (default 5)")
        q.add_argument("--worker-timeout", type=float, default=30.0, help="seconds to wait for a first worker (default 30)")

    def inputs(q, what):
        q.add_argument("input", metavar="INPUT", nargs="*", help=f"mesh files and folders of meshes to {what}")
        q.add_argument("--list", action="append", metavar="FILE", help="a file naming one mesh per line (# comments), repeatable")
        q.add_argument("--recursive", action="store_true", help="also the meshes in sub-folders (outputs keep the sub-folders)")

    b = sub.add_parser("bake", help="bake every mesh: OUT/<stem>-ao.<format>, and the other outputs asked for")
    inputs(b, "bake")
    b.add_argument("--size", default="1024", help="map size: N or WIDTHxHEIGHT (default 1024)")
    b.add_argument("--format", default="png", choices=["png", "exr", "tif"], help="map format (default png, 8 bit)")
    b.add_argument("-m", "--method", default="raytraced", help="the baker: raytraced (default) or histogram")
    b.add_argument("--uv-set", type=int, default=0, help="the UV set to bake into (default 0)")
    b.add_argument("--per-vertex", choices=["ply", "glb"], help="also per-vertex AO: OUT/<stem>-ao.ply or .glb (meshes without UVs: with --no-map)")
    b.add_argument("--no-map", action="store_true", help="no map: only the other outputs (--per-vertex, --gltf)")
    b.add_argument("--bent-normals", action="store_true", help="also the bent normals: OUT/<stem>-bent.png")
    b.add_argument("--bent-normals-space", choices=["world", "tangent"], help="the bent normals' space (ao bake --bent-normals-space; default world)")
    b.add_argument("--thickness", action="store_true", help="also the thickness map: OUT/<stem>-thickness.png (ao bake --thickness)")
    b.add_argument("--thickness-distance", type=float, help="R of the thickness, a fraction of each mesh's bounding-box diagonal (default 0.25)")
    b.add_argument("--cavity", action="store_true", help="also the cavity map: OUT/<stem>-cavity.png (ao bake --cavity)")
    b.add_argument("--cavity-distance", type=float, help="R of the cavity, a fraction of each mesh's bounding-box diagonal (default 0.02)")
    b.add_argument("--gltf", action="store_true", help="also a .glb with the map as its occlusion texture: OUT/<stem>-ao.glb")
    b.add_argument("-p", "--param", action="append", metavar="KEY=VALUE", help="a baker parameter (ao bake --help), repeatable")
    common(b)
    r = sub.add_parser("render", help="render the views of a JSON file: OUT/<output>")
    r.add_argument("input", metavar="VIEWS.json",
                   help='[{"scene", "camera": {...}, "method", "output", parameters...}, ...] or '
                        '{"turntable": N, "scene", "camera": {"eye", "target", ...}, "output": "stem", "format": "exr"}')
    common(r)
    c = sub.add_parser("compare", help="compare methods on every mesh: OUT/<stem>-compare.json and OUT/table.json")
    inputs(c, "compare the methods on")
    c.add_argument("--methods", help="comma-separated methods (default: every method but raytraced)")
    c.add_argument("--spp-reference", type=int, default=256, help="rays per pixel of the references (default 256)")
    common(c)
    return p


def _check_arguments(args):
    if args.local is not None and args.local < 1:
        raise Refused("--local: expected at least 1 worker")
    if not 0 <= args.threads <= 1024:
        raise Refused(f"--threads: expected an integer in [0, 1024], got {args.threads}")
    if not 0 <= args.retries <= 100:
        raise Refused(f"--retries: expected an integer in [0, 100], got {args.retries}")
    for name in ("status_seconds", "progress_seconds", "connect_timeout", "worker_timeout"):
        if not getattr(args, name) > 0:
            raise Refused(f"--{name.replace('_', '-')}: expected a number of seconds > 0")
    args.out_dir = os.path.abspath(args.out_dir)
    if args.log_dir:
        args.log_dir = os.path.abspath(args.log_dir)
    if args.progress_file:
        args.progress_file = os.path.abspath(args.progress_file)


def plan(args):
    """The tasks to run and those skipped; Refused for anything wrong with the arguments."""
    from . import _batch_jobs as jobs
    _check_arguments(args)
    check_out_dir(args.out_dir)
    tasks = {"bake": jobs.bake_tasks, "render": jobs.render_tasks, "compare": jobs.compare_tasks}[args.command](args)
    unique_outputs(tasks)
    todo, skipped, redo = classify(tasks, args.force, args.verify)
    return tasks, todo, skipped, redo


def _summary(status, redo, out):
    c = status.counts
    again = f", {len(redo)} of them made again (--force)" if redo else ""
    print(f"done {c['done']}{again}, failed {c['failed']}, skipped {c['skipped']} (already made with these settings)", file=out, flush=True)
    for name, reason in status.failed:
        print(f"  failed {name}: {reason}", file=out, flush=True)


def execute(args, out):
    """Plans, checks the cluster, runs; returns the exit code."""
    from . import _batch_cluster as cluster
    from . import _batch_jobs as jobs
    tasks, todo, skipped, redo = plan(args)
    status = cluster.Status(args.command, len(tasks), len(skipped), args.progress_file)
    status.write(force=True)
    if todo:
        client, local = cluster.connect(args, out)
        try:
            cluster.check_workers(client, args, out)
            cluster.run(client, todo, status, args, out)
        finally:
            if local is not None:
                # The in-process scheduler's closing chatter (after Ctrl-C, an event it was sending
                # when the client's comm closed is logged as CRITICAL) is not news to the user: the
                # batch says what happened. connect() silenced its warnings; now everything.
                logging.disable(logging.CRITICAL)
            client.close()
            if local is not None:
                local.close()
    if args.command == "compare":
        jobs.compare_table(args.out_dir, tasks)
    _summary(status, redo, out)
    return 1 if status.counts["failed"] else 0


def main(argv=None, out=sys.stdout):
    args = parser().parse_args(argv)
    from . import _batch_cluster as cluster
    try:
        return execute(args, out)
    except Refused as e:
        print(f"ao.batch: error: {e}", file=sys.stderr)
        return 2
    except cluster.Unusable as e:
        print(f"ao.batch: error: {e}", file=sys.stderr)
        return 3
    except KeyboardInterrupt:
        print("ao.batch: interrupted; the outputs made so far are kept, a rerun makes the others", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
