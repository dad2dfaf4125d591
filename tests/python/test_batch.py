# SPDX-License-Identifier: Apache-2.0
"""python3 -m ao.batch on a real Dask cluster: `dask scheduler` and `dask worker` processes on
127.0.0.1, each stopped by the test that started it (also when it fails).

- A folder of tiny meshes, one broken, baked while a worker is killed by its PID: every good output
  exists once with its record and is byte-identical to `ao bake`'s one-process run, the broken mesh
  is reported once, no temporary file is left, and a second run submits nothing.
- Reruns: the same settings skip every output; a changed mesh or a changed size is refused with
  one line naming what changed, and with --force exactly the changed outputs are made again.
- Checks before submitting: a -p typo is one line, exit 2, with no task reaching the scheduler;
  workers that cannot import ao are reported (exit 3) before any task; an unreachable scheduler is
  one line within seconds; a directory or FIFO named like an output is refused, never "skipped";
  a view's outputs outside --out-dir are refused.
- Farm features: per-vertex bakes of meshes without UVs from a list file and a recursive walk,
  per-task logs, progress of the running tasks at the client, retries of system failures only.
"""

import json
import os
import re
import shlex
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from conftest import bumpy_grid, read_ply_quality, run_cli, write_obj

SETTINGS = ["--size", "96", "-p", "samples=256"]
CLI_SETTINGS = ["-s", 96, "--spp", 256]


def start(cmd, log, env=None, shell=False):
    # Its own process group, so that stopping it reaches any child it started.
    return subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, start_new_session=True, env=env, shell=shell)


def stop(p):
    if p.poll() is None:
        os.killpg(p.pid, signal.SIGTERM)
        try:
            p.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()


class Cluster:
    """A scheduler and workers on 127.0.0.1; `worker_env` and `worker_prefix` (a shell prefix such
    as "ulimit -f 8;") change how the workers start."""

    def __init__(self, folder, workers=2, worker_env=None, worker_prefix="", wait=True):
        self.processes, self.logs, self.workers = [], [], []
        try:
            self._start(folder, workers, worker_env, worker_prefix, wait)
        except BaseException:
            self.close()  # a cluster that fails to start leaves no server behind
            raise

    def _start(self, folder, workers, worker_env, worker_prefix, wait):
        scheduler_file = folder / "scheduler.json"
        log = self._log(folder / "scheduler.log")
        self.processes.append(start(["dask", "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                                     "--scheduler-file", str(scheduler_file)], log))
        # The scheduler writes its file in place, not by a rename: wait until it is whole.
        deadline = time.monotonic() + 60
        info = None
        while info is None and time.monotonic() < deadline:
            try:
                info = json.loads(scheduler_file.read_text())
            except (FileNotFoundError, json.JSONDecodeError):
                time.sleep(0.05)
        assert info is not None, (folder / "scheduler.log").read_text()
        self.address = info["address"]
        assert self.address.startswith("tcp://127.0.0.1:")
        for k in range(workers):
            cmd = f"{worker_prefix} exec dask worker {self.address} --nthreads 1 --no-nanny --host 127.0.0.1 --no-dashboard --name w{k}" \
                  f" --local-directory {shlex.quote(str(folder / f'w{k}'))}"
            w = start(cmd, self._log(folder / f"worker{k}.log"), env=worker_env, shell=True)
            self.workers.append(w)
            self.processes.append(w)
        if wait:
            with self.client() as client:
                client.wait_for_workers(workers, timeout=60)

    def _log(self, path):
        f = open(path, "w")
        self.logs.append(f)
        return f

    def client(self):
        from distributed import Client
        return Client(self.address, timeout="30s")

    def task_prefixes(self):
        """Every task prefix the scheduler has seen: a batch that submits nothing adds none."""
        with self.client() as client:
            return set(client.run_on_scheduler(lambda dask_scheduler: list(dask_scheduler.task_prefixes)))

    def close(self):
        for p in reversed(self.processes):
            stop(p)
        for log in self.logs:
            log.close()


@pytest.fixture
def mesh_folder(tmp_path):
    folder = tmp_path / "meshes"
    folder.mkdir()
    for k in range(6):
        v, f, t = bumpy_grid(n=10, seed=k)
        write_obj(folder / f"grid{k}.obj", v, f, t)
    (folder / "broken.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 9/1\n")
    return folder


@pytest.fixture
def cluster(tmp_path):
    """A scheduler and two single-threaded workers without nannies (a killed worker stays dead)."""
    c = Cluster(tmp_path)
    try:
        yield c
    finally:
        c.close()


@pytest.fixture(scope="module")
def shared_cluster(tmp_path_factory):
    """One scheduler and two workers for the tests that kill nothing."""
    c = Cluster(tmp_path_factory.mktemp("cluster"))
    try:
        yield c
    finally:
        c.close()


def batch_cmd(command, *args):
    return [sys.executable, "-m", "ao.batch", command, *map(str, args)]


def batch(address, folder, out, *extra, **popen):
    cmd = batch_cmd("bake", folder, "--out-dir", out, "--scheduler", address, "--threads", 1, *SETTINGS, *extra)
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **popen)


def run_batch(*args, timeout=300):
    return subprocess.run(batch_cmd(*args), capture_output=True, text=True, timeout=timeout)


def outputs_and_records(names):
    return sorted(names + [n + ".ao.json" for n in names])


def one_error_line(p, code):
    """The run ended with `code` and one line "ao.batch: error: ..." on stderr, without a traceback."""
    assert p.returncode == code, (p.returncode, p.stdout, p.stderr)
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ao.batch: error: "), p.stderr
    return lines[0][len("ao.batch: error: "):]


def test_bake_folder_on_cluster_survives_a_lost_worker(ao_binary, mesh_folder, cluster, tmp_path):
    address, workers = cluster.address, cluster.workers
    reference = tmp_path / "reference"
    reference.mkdir()
    one = run_cli(ao_binary, "bake", mesh_folder, "--out-dir", reference, *CLI_SETTINGS, check=False)
    assert one.returncode == 1 and "broken.obj" in one.stderr  # the CLI's batch goes on past the broken mesh
    expected = sorted(os.listdir(reference))
    assert expected == [f"grid{k}-ao.png" for k in range(6)]

    out = tmp_path / "out"
    out.mkdir()
    # What a worker killed while writing leaves: its temporary file (write_file_atomically's name,
    # the pid of a process that has ended). The task that reruns the output removes it.
    ended = subprocess.Popen(["true"])
    ended.wait()
    (out / f".grid3-ao.tmp-{ended.pid}-0.png").write_bytes(b"half a PNG")
    p = batch(address, mesh_folder, out)
    lines = []
    try:
        lines.append(p.stdout.readline())
        assert lines[0] == "2 workers, each with ao " + __import__("ao").__version__ + "\n", lines[0] + p.stderr.read()
        lines.append(p.stdout.readline())
        assert lines[1].startswith("[1/7] "), lines[1] + p.stderr.read()
        with cluster.client() as client:
            w0 = next(a for a, w in client.scheduler_info()["workers"].items() if w["name"] == "w0")
            holding = client.processing(workers=[w0])[w0]
        assert holding, "worker w0 holds no task to lose"
        os.kill(workers[0].pid, signal.SIGKILL)  # mid-run: it holds tasks, one of them running
        rest, err = p.communicate(timeout=300)
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()
    assert workers[0].wait(timeout=10) == -signal.SIGKILL
    lines += rest.splitlines(keepends=True)
    text = "".join(lines)
    assert p.returncode == 1, text + err
    progress = [line for line in lines if line.startswith("[")]
    assert len(progress) == 7, text
    assert sum("broken.obj" in line for line in progress) == 1 and "failed broken.obj: " in text
    # A task the killed worker had finished writing (the rename is the commit) but not reported runs
    # again on the other worker and finds its output there with its record: skipped, not redone.
    summary = re.search(r"done (\d+), failed 1, skipped (\d+)", text)
    assert summary and int(summary[1]) + int(summary[2]) == 6 and int(summary[2]) <= len(holding), text
    assert sorted(os.listdir(out)) == outputs_and_records(expected)  # each once, no temporary file (hidden .*.tmp-*)
    for name in expected:
        assert (out / name).read_bytes() == (reference / name).read_bytes(), name

    times = {name: os.stat(out / name).st_mtime_ns for name in expected}
    again = batch(address, mesh_folder, out)
    text2, err2 = again.communicate(timeout=300)
    assert again.returncode == 1, text2 + err2  # the broken mesh fails again; nothing else runs
    assert "done 0, failed 1, skipped 6" in text2 and sum(line.startswith("[") for line in text2.splitlines()) == 1, text2
    assert {name: os.stat(out / name).st_mtime_ns for name in expected} == times


def small_meshes(folder, count=3, n=6):
    folder.mkdir()
    for k in range(count):
        write_obj(folder / f"grid{k}.obj", *bumpy_grid(n=n, seed=k))
    return folder


def test_rerun_redoes_exactly_the_changed_outputs(shared_cluster, tmp_path):
    meshes, out = small_meshes(tmp_path / "meshes"), tmp_path / "out"
    args = ["bake", meshes, "--out-dir", out, "--scheduler", shared_cluster.address, "--threads", 1, "--size", 32, "-p", "samples=8"]
    first = run_batch(*args)
    assert first.returncode == 0 and "done 3, failed 0, skipped 0" in first.stdout, first.stdout + first.stderr
    record = json.loads((out / "grid0-ao.png.ao.json").read_text())
    assert record["ao"]["version"] and record["ao"]["simd_target"] and record["settings"]["width"] == 32
    import hashlib
    assert record["inputs"][0]["sha256"] == hashlib.sha256((meshes / "grid0.obj").read_bytes()).hexdigest()
    assert record["output"]["sha256"] == hashlib.sha256((out / "grid0-ao.png").read_bytes()).hexdigest()
    times = {n: os.stat(out / n).st_mtime_ns for n in os.listdir(out)}

    same = run_batch(*args)
    assert same.returncode == 0 and "done 0, failed 0, skipped 3" in same.stdout and "workers" not in same.stdout, same.stdout
    # One mesh changed: refused naming it; with --force, that output alone is made again.
    write_obj(meshes / "grid1.obj", *bumpy_grid(n=6, seed=9))
    refused = run_batch(*args)
    assert "grid1-ao.png was made otherwise (input grid1.obj changed)" in one_error_line(refused, 2)
    forced = run_batch(*args, "--force")
    assert forced.returncode == 0 and "done 1, 1 of them made again (--force), failed 0, skipped 2" in forced.stdout, forced.stdout
    changed = {n for n in os.listdir(out) if os.stat(out / n).st_mtime_ns != times[n]}
    assert changed == {"grid1-ao.png", "grid1-ao.png.ao.json"}
    # Another size: every output was made otherwise.
    bigger = [a if a != 32 else 48 for a in args]
    message = one_error_line(run_batch(*bigger), 2)
    assert "was made otherwise (height 32 -> 48, width 32 -> 48); 2 more outputs too: rerun with --force" in message, message
    assert run_batch(*bigger, "--force").returncode == 0
    assert all(json.loads((out / f"grid{k}-ao.png.ao.json").read_text())["settings"]["width"] == 48 for k in range(3))


def test_bake_folder_writes_the_ao_family(ao_binary, shared_cluster, tmp_path):
    meshes, out = small_meshes(tmp_path / "meshes", count=2), tmp_path / "out"
    settings = ["--size", 32, "-p", "samples=8", "-p", "spread_angle=150"]
    p = run_batch("bake", meshes, "--out-dir", out, "--scheduler", shared_cluster.address, "--threads", 1, *settings, "--bent-normals",
                  "--bent-normals-space", "tangent", "--thickness", "--thickness-distance", 0.3, "--cavity")
    assert p.returncode == 0 and "done 2, failed 0, skipped 0" in p.stdout, p.stdout + p.stderr
    kinds = ["ao", "bent", "thickness", "cavity"]
    assert sorted(os.listdir(out)) == outputs_and_records([f"grid{k}-{kind}.png" for k in range(2) for kind in kinds])
    for k in range(2):
        cli = tmp_path / f"cli{k}"
        run_cli(ao_binary, "bake", meshes / f"grid{k}.obj", "--size", 32, "--samples", 8, "--spread-angle", 150, "-o", cli.with_suffix(".ao.png"),
                "--bent-normals", cli.with_suffix(".bent.png"), "--bent-normals-space", "tangent", "--thickness", cli.with_suffix(".thickness.png"),
                "--thickness-distance", 0.3, "--cavity", cli.with_suffix(".cavity.png"))
        for kind in kinds:
            assert (out / f"grid{k}-{kind}.png").read_bytes() == cli.with_suffix(f".{kind}.png").read_bytes(), (k, kind)
    record = json.loads((out / "grid0-thickness.png.ao.json").read_text())["settings"]
    assert record["thickness_distance"] == pytest.approx(0.3) and record["bent_normal_space"] == "tangent"


def test_every_submission_has_its_own_key():
    # A scheduler hands a finished key's result to any client that submits that key before it has
    # forgotten it: a key made of the task alone let a rerun with other settings receive the run
    # before it's result, its outputs left stale (seen under load in the test above).
    from ao import _batch_cluster
    task = {"kind": "bake", "name": "/m/grid0.obj", "outputs": ["/o/grid0-ao.png"]}
    assert _batch_cluster._key(task) != _batch_cluster._key(task)
    assert _batch_cluster._key(task).startswith("ao-bake-grid0.obj-")


def test_bad_arguments_fail_once_before_submitting(shared_cluster, tmp_path):
    meshes, out = small_meshes(tmp_path / "meshes", count=2), tmp_path / "out"
    before = shared_cluster.task_prefixes()
    started = time.monotonic()
    typo = run_batch("bake", meshes, "--out-dir", out, "--scheduler", shared_cluster.address, "-p", "sampels=4")
    assert one_error_line(typo, 2).startswith("bake raytraced: unknown parameter 'sampels' (known: samples,")
    assert time.monotonic() - started < 30 and typo.stdout == ""
    wrong_type = run_batch("bake", meshes, "--out-dir", out, "--scheduler", shared_cluster.address, "--size", "big")
    assert one_error_line(wrong_type, 2).startswith("size: expected N or WIDTHxHEIGHT")
    views = tmp_path / "views.json"
    views.write_text(json.dumps([{"scene": "wedge", "method": "gtoa", "output": "a.exr"}]))
    method = run_batch("render", views, "--out-dir", out, "--scheduler", shared_cluster.address)
    assert one_error_line(method, 2).startswith(f"{views}: view 0: method: unknown 'gtoa'") or "gtoa" in method.stderr
    assert shared_cluster.task_prefixes() == before  # nothing reached the scheduler
    assert os.listdir(out) == []


def test_workers_without_ao_are_reported_before_any_task(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}  # Debian's interpreter alone: no ao
    c = Cluster(tmp_path, workers=1, worker_env=env)
    try:
        before = c.task_prefixes()
        p = run_batch("bake", small_meshes(tmp_path / "meshes", count=2), "--out-dir", tmp_path / "out", "--scheduler", c.address)
        message = one_error_line(p, 3)
        assert "1 of 1 workers cannot run ao" in message and "No module named 'ao'" in message, message
        assert c.task_prefixes() == before and os.listdir(tmp_path / "out") == []
    finally:
        c.close()


def test_unreachable_scheduler_is_one_line_within_seconds(tmp_path):
    import socket
    with socket.socket() as s:  # a port nobody listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    started = time.monotonic()
    p = run_batch("bake", small_meshes(tmp_path / "meshes", count=1), "--out-dir", tmp_path / "out", "--scheduler",
                  f"tcp://127.0.0.1:{port}", "--connect-timeout", 1)
    assert one_error_line(p, 3).startswith(f"cannot reach the scheduler at tcp://127.0.0.1:{port} within 1 s")
    assert time.monotonic() - started < 20


def test_only_complete_files_are_done(tmp_path):
    # A directory or a FIFO named like an output is not a made output: refused, one line, exit 2.
    meshes = small_meshes(tmp_path / "meshes", count=2)
    for make in (os.mkdir, os.mkfifo):
        out = tmp_path / f"out-{make.__name__}"
        out.mkdir()
        make(out / "grid0-ao.png")
        p = run_batch("bake", meshes, "--out-dir", out, "--scheduler", "tcp://127.0.0.1:9")
        message = one_error_line(p, 2)
        assert "grid0-ao.png" in message and ("directory" in message or "FIFO" in message), message
        assert "skipped" not in p.stdout


def test_view_outputs_stay_in_the_output_folder(shared_cluster, tmp_path):
    out = tmp_path / "out"
    outside = tmp_path / "outside"
    outside.mkdir()
    (out / "sub").mkdir(parents=True)
    os.symlink(outside, out / "link")
    views = tmp_path / "views.json"
    cases = [({"output": "../x.exr"}, "output: '../x.exr' leaves --out-dir"),
             ({"output": str(tmp_path / "abs.exr")}, "leaves --out-dir"),
             ({"output": "a.exr", "shaded": "../s.png"}, "shaded: '../s.png' leaves --out-dir"),
             ({"output": "a.exr", "gbuffer_output": "/tmp/g.exr"}, "gbuffer_output: '/tmp/g.exr' leaves --out-dir"),
             ({"output": "link/a.exr"}, "leads out of --out-dir through a symbolic link")]
    for fields, needle in cases:
        views.write_text(json.dumps([{"scene": "wedge", "camera": {"width": 16, "height": 9}, **fields}]))
        p = run_batch("render", views, "--out-dir", out, "--scheduler", "tcp://127.0.0.1:9")
        assert needle in one_error_line(p, 2), (needle, p.stderr)
    assert os.listdir(outside) == [] and not (tmp_path / "x.exr").exists()
    views.write_text(json.dumps([{"scene": "wedge", "method": "volumetric", "camera": {"width": 16, "height": 9}, "output": "sub/a.exr",
                                  "shaded": "sub/a-shaded.png", "gbuffer_output": "sub/a-g.exr"}]))
    p = run_batch("render", views, "--out-dir", out, "--scheduler", shared_cluster.address)
    assert p.returncode == 0, p.stdout + p.stderr
    assert sorted(os.listdir(out / "sub")) == outputs_and_records(["a-g.exr", "a-shaded.png", "a.exr"])


def test_per_vertex_bakes_from_a_list_and_sub_folders(ao_binary, shared_cluster, tmp_path):
    # Meshes without UVs: per-vertex AO only. Sub-folders keep their names under --out-dir.
    top = tmp_path / "assets"
    (top / "props").mkdir(parents=True)
    v, f, _ = bumpy_grid(n=6, seed=1)
    write_obj(top / "a.obj", v, f)
    write_obj(top / "props" / "b.obj", *bumpy_grid(n=6, seed=2)[:2])
    extra = tmp_path / "elsewhere"
    extra.mkdir()
    write_obj(extra / "c.obj", *bumpy_grid(n=6, seed=3)[:2])
    listing = tmp_path / "list.txt"
    listing.write_text("# one per line\nelsewhere/c.obj\n\n")
    out, logs = tmp_path / "out", tmp_path / "logs"
    p = run_batch("bake", top, "--recursive", "--list", listing, "--per-vertex", "ply", "--no-map", "-p", "samples=16", "--out-dir", out,
                  "--log-dir", logs, "--scheduler", shared_cluster.address)
    assert p.returncode == 0 and "done 3, failed 0" in p.stdout, p.stdout + p.stderr
    made = sorted(os.path.relpath(os.path.join(d, n), out) for d, _, names in os.walk(out) for n in names)
    assert made == outputs_and_records(["a-ao.ply", "c-ao.ply", "props/b-ao.ply"])
    cli = tmp_path / "cli.ply"
    run_cli(ao_binary, "bake", top / "props" / "b.obj", "--per-vertex", cli, "--spp", 16)
    np.testing.assert_array_equal(read_ply_quality(out / "props" / "b-ao.ply"), read_ply_quality(cli))
    log = (logs / "props" / "b.obj.log").read_text()
    assert "== props/b.obj on " in log and "per-vertex b.obj 100%" in log and "done in " in log, log


def test_progress_of_long_tasks_reaches_the_client(shared_cluster, tmp_path):
    meshes = small_meshes(tmp_path / "meshes", count=1, n=24)
    progress = tmp_path / "progress.json"
    p = run_batch("bake", meshes, "--out-dir", tmp_path / "out", "--size", 256, "-p", "samples=128", "--threads", 1,
                  "--status-seconds", 0.2, "--progress-seconds", 0.1, "--progress-file", progress, "--scheduler", shared_cluster.address)
    assert p.returncode == 0, p.stdout + p.stderr
    running = re.findall(r"running grid0\.obj bake grid0\.obj (\d+)%", p.stdout)
    assert running, p.stdout  # a status line named the running task's stage and how far it was
    state = json.loads(progress.read_text())
    assert (state["total"], state["done"], state["failed"], state["skipped"], state["running"]) == (1, 1, 0, 0, {})
    assert state["ao"]["version"] and state["eta_s"] == 0


def test_system_failures_are_retried_and_bad_input_is_not(tmp_path):
    # A worker whose files may not exceed 8 KiB (SIGXFSZ ignored, so a write fails with EFBIG as on
    # a full disk): every map fails to be written, an OSError, retried; the broken mesh fails once.
    c = Cluster(tmp_path, workers=1, worker_prefix="trap '' XFSZ; ulimit -f 8;")
    try:
        meshes = small_meshes(tmp_path / "meshes", count=1)
        (meshes / "broken.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 9/1\n")
        logs = tmp_path / "logs"
        p = run_batch("bake", meshes, "--out-dir", tmp_path / "out", "--size", 256, "-p", "samples=1", "--retries", 2, "--log-dir", logs,
                      "--scheduler", c.address)
        assert p.returncode == 1, p.stdout + p.stderr
        assert re.search(r"failed grid0\.obj: OSError: .*grid0-ao\.png", p.stdout), p.stdout
        assert (logs / "grid0.obj.log").read_text().count("== grid0.obj on ") == 3  # the first run and two retries
        assert (logs / "broken.obj.log").read_text().count("== broken.obj on ") == 1
        assert [n for n in os.listdir(tmp_path / "out") if n.startswith(".")] == []  # no temporary file left
    finally:
        c.close()


def test_ctrl_c_is_one_line(tmp_path):
    meshes = small_meshes(tmp_path / "meshes", count=2, n=24)
    p = subprocess.Popen(batch_cmd("bake", meshes, "--out-dir", tmp_path / "out", "--local", 1, "--size", 1024, "-p", "samples=1024"),
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().startswith("1 workers, each with ao")
        time.sleep(0.5)
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=60)
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()
    assert p.returncode == 130, out + err
    assert err.strip() == "ao.batch: interrupted; the outputs made so far are kept, a rerun makes the others", err
