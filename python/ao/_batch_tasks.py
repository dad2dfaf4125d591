# SPDX-License-Identifier: Apache-2.0
"""The tasks of ao.batch, run on the Dask workers: one bake, render or compare each, described by a
dict the client made and checked (ao/_batch_plan.py).

A task first looks at its outputs: when each is a complete file whose record (OUTPUT.ao.json) says
it was made from the same inputs and settings, the task is skipped (a worker lost after it
committed them, and the scheduler ran the task again). Otherwise it removes the temporary files
other processes left for its outputs and runs the job, which writes the outputs and their records
as one transaction. Bad input becomes a "failed" result with its one line, never retried; any
other exception (OSError, a lost file system) propagates, so that Dask retries the task as many
times as the client allows. Progress of the job goes to the client as Dask events (topic
EVENTS) and, with a log folder, into the task's log file with its warnings and its result.
"""

import json
import os
import socket
import time
import warnings

EVENTS = "ao-batch"


class _Log:
    """The task's log file, appended to line by line (each attempt adds its own lines), or nothing."""

    def __init__(self, path):
        self.file = open(path, "a", buffering=1, encoding="utf-8") if path else None

    def line(self, text):
        if self.file:
            self.file.write(time.strftime("%Y-%m-%d %H:%M:%S ") + text + "\n")

    def close(self):
        if self.file:
            self.file.close()


def _publisher(name, log, seconds):
    """The job's progress callable: an event to the client and a log line, each stage at most every
    `seconds` (and at its end)."""
    try:
        from distributed import get_worker
        worker = get_worker()
    except (ImportError, ValueError):
        worker = None
    last = {"stage": None, "at": 0.0, "done": None}

    def progress(stage, done, total):
        now = time.monotonic()
        if stage == last["stage"] and (done == last["done"] or (now - last["at"] < seconds and done < total)):
            return
        last.update(stage=stage, at=now, done=done)
        percent = round(100 * done / total) if total else None
        log.line(f"{stage} {percent}%" if percent is not None else f"{stage} ...")
        if worker is not None:
            worker.log_event(EVENTS, {"task": name, "stage": stage, "done": done, "total": total})
    return progress


def _already_made(spec):
    """True when every output is complete and recorded as the client expects (records.made)."""
    from . import _batch_records as records
    if any(records.output_state(o) != "file" for o in spec["outputs"]):
        return False
    previous = records.read(records.record_path(spec["outputs"][0]))
    expected = records.hash_inputs(spec["record"], previous)
    return records.made(spec["outputs"], expected)[0] == "done"


def _compare(spec, progress):
    """ao.compare's rows for one mesh into a JSON file, then that file's record."""
    import hashlib

    from . import _ao
    from . import _batch_records as records
    call = spec["call"]
    record = records.hash_inputs(spec["record"])
    out = _ao.compare(call["mesh"], call["request"], progress)
    text = json.dumps({"ao": _ao.build_info(), "mesh": os.path.basename(call["mesh"]), "rows": out["table"]["rows"]}, indent=1) + "\n"
    path = spec["outputs"][0]
    _ao.write_text(path, text)
    data = text.encode()
    record["output"] = {"file": os.path.basename(path), "bytes": len(data), "sha256": hashlib.sha256(data).hexdigest()}
    record["outputs"] = [os.path.basename(path)]
    _ao.write_text(records.record_path(path), json.dumps(record, indent=1) + "\n")


def _job(spec, progress):
    from . import _ao
    call = spec["call"]
    if spec["kind"] == "bake":
        _ao.bake(call["mesh"], call["request"], progress)
    elif spec["kind"] == "render":
        _ao.render(call["scene"], None, call["request"], progress)
    else:
        _compare(spec, progress)


def run_task(spec):
    """Runs one task (its spec from the client); returns {"status": "done" | "skipped" | "failed",
    "name", "seconds", "worker", "reason" (failed), "warnings"}."""
    import ao
    from . import _batch_records as records
    name = spec["name"]
    worker = socket.gethostname() + ":" + str(os.getpid())
    result = {"name": name, "worker": worker, "warnings": []}
    log = _Log(spec.get("log"))
    log.line(f"== {name} on {worker}: ao {ao.__version__}, {spec['kind']}")
    try:
        if _already_made(spec):
            log.line("skipped: every output is there, made from the same inputs and settings")
            return dict(result, status="skipped")
        for out in spec["outputs"]:
            ao._ao.remove_abandoned_temporaries(out)
            ao._ao.remove_abandoned_temporaries(records.record_path(out))
        ao.set_threads(spec["threads"])
        started = time.monotonic()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                _job(spec, _publisher(name, log, spec.get("progress_seconds", 2.0)))
            except (ao.InputError, TypeError, ValueError) as e:
                log.line(f"failed: {e}")
                return dict(result, status="failed", reason=str(e), warnings=[str(w.message) for w in caught])
            finally:
                for w in caught:
                    log.line(f"warning: {w.message}")
        seconds = time.monotonic() - started
        log.line(f"done in {seconds:.2f} s: " + ", ".join(spec["outputs"]))
        return dict(result, status="done", seconds=seconds, warnings=[str(w.message) for w in caught])
    except BaseException as e:
        log.line(f"system failure: {type(e).__name__}: {e} (Dask retries it when retries remain)")
        raise
    finally:
        log.close()


def environment_check():
    """What ao.batch asks of every worker before it submits a task: the interpreter, and ao's
    version or why it cannot be imported. The function is made in a closure, so cloudpickle sends
    its code by value and it runs on a worker without ao (a reference into ao would not unpickle
    there); it imports only the standard library unless ao is there."""
    def check():
        import importlib
        import sys
        info = {"python": sys.executable, "version": None, "error": None}
        try:
            module = importlib.import_module("ao")
            info["version"] = getattr(module, "__version__", "?")
        except Exception as e:  # ModuleNotFoundError, or an ao that fails to load (a wrong ABI)
            info["error"] = f"{type(e).__name__}: {e}"
        return info
    return check
