"""python3 -m ao.batch on a real Dask cluster: a `dask scheduler` and two `dask worker` processes on
127.0.0.1 (each stopped by the test, also when it fails) bake a folder of tiny meshes, one of them
broken, while one worker is killed by its PID in the middle. Every good output must exist once and
be byte-identical to `ao bake`'s one-process run, the broken mesh be reported once, no temporary
file be left, and a second run bake nothing."""

import json
import os
import re
import signal
import subprocess
import sys
import time

import pytest

from conftest import bumpy_grid, run_cli, write_obj

SETTINGS = ["--size", "96", "-p", "samples=256"]
CLI_SETTINGS = ["-s", 96, "--spp", 256]


def start(cmd, log):
    # Its own process group, so that stopping it reaches any child it started.
    return subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)


def stop(p):
    if p.poll() is None:
        os.killpg(p.pid, signal.SIGTERM)
        try:
            p.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()


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
    processes, logs = [], []
    scheduler_file = tmp_path / "scheduler.json"
    env_log = open(tmp_path / "scheduler.log", "w")
    logs.append(env_log)
    try:
        processes.append(start(["dask", "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                                "--scheduler-file", str(scheduler_file)], env_log))
        deadline = time.monotonic() + 60
        while not scheduler_file.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        assert scheduler_file.exists(), (tmp_path / "scheduler.log").read_text()
        address = json.loads(scheduler_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        workers = []
        for k in range(2):
            log = open(tmp_path / f"worker{k}.log", "w")
            logs.append(log)
            workers.append(start(["dask", "worker", address, "--nthreads", "1", "--no-nanny", "--host", "127.0.0.1",
                                  "--no-dashboard", "--name", f"w{k}"], log))
        processes += workers
        from distributed import Client
        with Client(address, timeout="30s") as client:
            client.wait_for_workers(2, timeout=60)
        yield address, workers
    finally:
        for p in reversed(processes):
            stop(p)
        for log in logs:
            log.close()


def batch(address, folder, out, **popen):
    cmd = [sys.executable, "-m", "ao.batch", "bake", str(folder), "--out-dir", str(out), "--scheduler", address, "--threads", "1",
           *SETTINGS]
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **popen)


def test_bake_folder_on_cluster_survives_a_lost_worker(ao_binary, mesh_folder, cluster, tmp_path):
    address, workers = cluster
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
        assert lines[0].startswith("[1/7] "), lines[0] + p.stderr.read()
        from distributed import Client
        with Client(address, timeout="30s") as client:
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
    # again on the other worker and finds its output there: skipped, not redone (batch.py).
    summary = re.search(r"done (\d+), failed 1, skipped (\d+)", text)
    assert summary and int(summary[1]) + int(summary[2]) == 6 and int(summary[2]) <= len(holding), text
    assert sorted(os.listdir(out)) == expected  # each output once, no temporary file (hidden .*.tmp-*)
    for name in expected:
        assert (out / name).read_bytes() == (reference / name).read_bytes(), name

    times = {name: os.stat(out / name).st_mtime_ns for name in expected}
    again = batch(address, mesh_folder, out)
    text2, err2 = again.communicate(timeout=300)
    assert again.returncode == 1, text2 + err2  # the broken mesh fails again; nothing else runs
    assert "done 0, failed 1, skipped 6" in text2 and sum(line.startswith("[") for line in text2.splitlines()) == 1, text2
    assert {name: os.stat(out / name).st_mtime_ns for name in expected} == times
