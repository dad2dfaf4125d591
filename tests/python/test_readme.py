# SPDX-License-Identifier: Apache-2.0
"""The README's Python examples run as written (the "Python" section's python block)."""

import contextlib
import io
import os
import re

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def readme_blocks(section, language):
    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as f:
        text = f.read()
    body = text.split(f"\n## {section}\n", 1)[1].split("\n## ", 1)[0]
    return re.findall(rf"```{language}\n(.*?)```", body, re.S)


def test_python_section_runs(tmp_path, monkeypatch):
    blocks = readme_blocks("Python", "python")
    assert len(blocks) == 1
    monkeypatch.chdir(tmp_path)
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        exec(compile(blocks[0], "README.md", "exec"), {})
    lines = printed.getvalue().splitlines()
    assert lines[0].startswith("[('alchemy', ") and "('gtao', " in lines[0]
    assert lines[1] == "gtao: slices must be an integer in [1, 16], got 0"
    assert list(tmp_path.iterdir()) == []  # the examples write no file


def test_cluster_section_runs(tmp_path):
    import json
    import subprocess
    import sys

    from conftest import bumpy_grid, write_obj

    (views,) = readme_blocks("Cluster", "json")
    (commands,) = readme_blocks("Cluster", "sh")
    (tmp_path / "views.json").write_text(views)
    (tmp_path / "meshes").mkdir()
    for k in range(2):
        write_obj(tmp_path / "meshes" / f"grid{k}.obj", *bumpy_grid(n=6, seed=k))
    for line in commands.strip().splitlines():
        cmd = line.split("#")[0].split()
        assert cmd[0] == "/usr/bin/python3"
        p = subprocess.run([sys.executable, *cmd[1:]], cwd=tmp_path, capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, line + "\n" + p.stdout + p.stderr
        assert p.stdout.splitlines()[-1].endswith("failed 0, skipped 0 (already made with these settings)"), p.stdout
    with_records = lambda names: sorted(names + [n + ".ao.json" for n in names])  # noqa: E731
    assert sorted(os.listdir(tmp_path / "maps")) == with_records(["grid0-ao.png", "grid1-ao.png"])
    assert sorted(os.listdir(tmp_path / "frames")) == with_records([f"wedge-{k:04d}.exr" for k in range(4)])
    with open(tmp_path / "cmp" / "table.json") as f:
        rows = json.load(f)["rows"]
    assert sorted((r["mesh"], r["method"]) for r in rows) == [(m, a) for m in ("grid0.obj", "grid1.obj") for a in ("alchemy", "gtao")]
