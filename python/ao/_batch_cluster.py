# SPDX-License-Identifier: Apache-2.0
"""The cluster side of ao.batch, on the client: connecting to the scheduler (or starting local
workers), checking every worker's environment before a task is submitted, submitting the tasks,
and following them: a line per finished task, a status line with the running tasks' progress and
the time left, and the machine-readable progress file.
"""

import json
import logging
import os
import threading
import time
import uuid

from . import _ao
from ._batch_tasks import EVENTS, environment_check, run_task


class Unusable(Exception):
    """The cluster cannot run the batch (no scheduler, workers without ao): one line, exit 3."""


def connect(args, out):
    """A Client (and the LocalCluster it owns, or None)."""
    from distributed import Client, LocalCluster
    if args.local is not None:
        # On 127.0.0.1 only, the scheduler's HTTP server on a free port, and Dask's own log lines
        # (a worker still busy when Ctrl-C closes it) below errors: the batch says what happened.
        logging.disable(logging.WARNING)  # the client process logs nothing else; also while the cluster closes
        cluster = LocalCluster(n_workers=args.local, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address="127.0.0.1:0",
                               silence_logs=logging.ERROR)
        return Client(cluster), cluster
    try:
        client = Client(args.scheduler, timeout=f"{args.connect_timeout}s")
    except (OSError, TimeoutError) as e:
        raise Unusable(f"cannot reach the scheduler at {args.scheduler} within {args.connect_timeout:g} s "
                       f"({type(e).__name__}); is `dask scheduler` running there?")
    return client, None


def check_workers(client, args, out):
    """Every worker can import ao, the client's version; Unusable naming the ones that cannot."""
    deadline = time.monotonic() + args.worker_timeout
    while not client.scheduler_info().get("workers") and time.monotonic() < deadline:
        time.sleep(0.2)
    if not client.scheduler_info().get("workers"):
        raise Unusable(f"the scheduler has no workers (waited {args.worker_timeout:g} s); start `dask worker` processes (docs/cluster.md)")
    found = client.run(environment_check(), on_error="return")
    bad = []
    for address, info in sorted(found.items()):
        if isinstance(info, BaseException):
            bad.append(f"{address}: {type(info).__name__}: {info}")
        elif info["error"]:
            bad.append(f"{address} ({info['python']}): {info['error']}")
        elif info["version"] != _ao.__version__:
            bad.append(f"{address} ({info['python']}): ao {info['version']}, the client {_ao.__version__}")
    if bad:
        more = f"; {len(bad) - 1} more" if len(bad) > 1 else ""
        raise Unusable(f"{len(bad)} of {len(found)} workers cannot run ao {_ao.__version__}: {bad[0]}{more} "
                       "(start them with the interpreter ao is installed for: docs/cluster.md, \"Setting up machines\")")
    print(f"{len(found)} workers, each with ao {_ao.__version__}", file=out, flush=True)


class Status:
    """What the client knows of the run: counts, the tasks running with their progress (from the
    workers' events), and the progress file, rewritten atomically at most every second."""

    def __init__(self, command, total, skipped, path):
        self.command, self.total, self.path = command, total, path
        self.counts = {"done": 0, "failed": 0, "skipped": skipped}
        self.running = {}  # name -> {"stage", "done", "total", "since"}
        self.failed = []   # (name, reason)
        self.started = time.monotonic()
        self.lock = threading.Lock()
        self.written = 0.0

    def event(self, event):
        """A worker's progress event (Dask's (time, message))."""
        msg = event[1]
        with self.lock:
            self.running.setdefault(msg["task"], {"since": time.monotonic()}).update(stage=msg["stage"], done=msg["done"], total=msg["total"])
        self.write()

    def finished(self, name, status, reason=None):
        with self.lock:
            self.running.pop(name, None)
            self.counts[status] += 1
            if reason is not None:
                self.failed.append((name, reason))
        self.write(force=True)

    def eta(self):
        """Seconds left at the rate tasks finished so far (None before the first)."""
        made = self.counts["done"] + self.counts["failed"]
        left = self.total - made - self.counts["skipped"]
        if made == 0:
            return None
        return (time.monotonic() - self.started) / made * left

    def line(self):
        """The status line: counts, time left and each running task's stage."""
        with self.lock:
            running = [f"{n} {r['stage']} {round(100 * r['done'] / r['total'])}%" if r.get("total") else f"{n} {r.get('stage', 'starting')}"
                       for n, r in sorted(self.running.items())]
        eta = self.eta()
        left = f", about {eta:.0f} s left" if eta is not None else ""
        return f"... done {self.counts['done']}, failed {self.counts['failed']}, skipped {self.counts['skipped']} of {self.total}{left}" + \
            (f"; running {'; '.join(running[:4])}" if running else "")

    def write(self, force=False):
        if not self.path:
            return
        now = time.monotonic()
        if not force and now - self.written < 1.0:
            return
        with self.lock:
            self.written = now
            state = {"ao": _ao.build_info(), "command": self.command, "total": self.total, **self.counts,
                     "running": {n: {k: v for k, v in r.items() if k != "since"} for n, r in self.running.items()},
                     "elapsed_s": round(now - self.started, 3), "eta_s": None if self.eta() is None else round(self.eta(), 1),
                     "failed_tasks": [{"name": n, "reason": r} for n, r in self.failed], "updated": time.strftime("%Y-%m-%dT%H:%M:%S%z")}
            _ao.write_text(self.path, json.dumps(state, indent=1) + "\n")


def _spec(task, args):
    """What a worker gets: the task, the threads, its log file."""
    spec = dict(task, threads=args.threads, progress_seconds=args.progress_seconds)
    if args.log_dir:
        spec["log"] = os.path.join(args.log_dir, task["name"] + ".log")
        os.makedirs(os.path.dirname(spec["log"]), exist_ok=True)
    return spec


def _key(task):
    # Unique to this submission: a scheduler keeps a finished key's result until every client that
    # held it is gone, and hands it to any client that submits the same key meanwhile. A key made
    # of the task alone let a rerun with other settings (--size 48 after 32, --force) receive the
    # result of the run before it, its outputs left as they were, when the scheduler had not yet
    # forgotten that run's keys.
    return f"ao-{task['kind']}-{os.path.basename(task['name'])}-{uuid.uuid4().hex}"


def run(client, tasks, status, args, out):
    """Submits the tasks and follows them to the end; prints a line per finished task and a status
    line every --status-seconds."""
    from distributed import as_completed
    client.subscribe_topic(EVENTS, status.event)
    futures = {client.submit(run_task, _spec(t, args), key=_key(t), pure=False, retries=args.retries): t for t in tasks}
    queue = as_completed(futures, with_results=False)
    last_line = time.monotonic()
    k = 0
    while not queue.is_empty():
        batch = queue.next_batch(block=False)
        if not batch:
            if time.monotonic() - last_line >= args.status_seconds:
                print(status.line(), file=out, flush=True)
                last_line = time.monotonic()
            status.write()
            time.sleep(0.05)
            continue
        for future in batch:
            k += 1
            task = futures[future]
            _report(k, len(tasks), task, future, status, out)
    client.unsubscribe_topic(EVENTS)


def _report(k, n, task, future, status, out):
    name = task["name"]
    try:
        result = future.result()
    except Exception as e:  # a system failure on the worker after its retries, or the worker lost too often
        result = {"status": "failed", "reason": f"{type(e).__name__}: {e}"}
    state = result["status"]
    if state == "done":
        print(f"[{k}/{n}] done {name} -> {', '.join(task['outputs'])} ({result['seconds']:.2f} s)", file=out, flush=True)
    elif state == "skipped":
        print(f"[{k}/{n}] skipped {name}: made before, by a worker that was lost", file=out, flush=True)
    else:
        print(f"[{k}/{n}] failed {name}: {result['reason']}", file=out, flush=True)
    status.finished(name, state, result.get("reason"))
