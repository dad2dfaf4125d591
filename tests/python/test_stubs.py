# SPDX-License-Identifier: Apache-2.0
"""The type stubs (python/ao/*.pyi, installed with the package) agree with the module: mypy's
stubtest (Debian's python3-mypy) compares every stubbed name, signature and default with the
module as imported, and type-checks the stubs themselves."""

import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def mypy(*args, cwd):
    return subprocess.run([sys.executable, "-m", *args], cwd=cwd, capture_output=True, text=True, timeout=600)


def test_stubs_match_the_module(tmp_path):
    p = mypy("mypy.stubtest", "ao", "--concise", "--allowlist", os.path.join(HERE, "stubtest-allowlist.txt"), "--mypy-config-file",
             os.path.join(HERE, "stubtest-mypy.ini"), cwd=tmp_path)  # its cache goes to the temporary folder
    assert p.returncode == 0, p.stdout + p.stderr

