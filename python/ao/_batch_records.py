# SPDX-License-Identifier: Apache-2.0
"""Provenance records for ao.batch: what made an output, beside it as OUTPUT.ao.json (the library's
format, src/ao/jobs/provenance.h). The client computes the record a task would write (the
library's record of the request, with the inputs' SHA-256 added here) and compares it with the one
on disk, to tell an output made from the same inputs and settings (skipped) from a stale one
(redone with --force, refused otherwise) and from one that is missing or incomplete (made).

An input is hashed again only when its size or modification time differs from what the record on
disk says (the quick check rsync and make use); --verify hashes every input.
"""

import hashlib
import json
import os
import stat

RECORD_SUFFIX = ".ao.json"


def record_path(output):
    return output + RECORD_SUFFIX


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def read(path):
    """The record at `path`, or None when there is none (or it is not a readable JSON object)."""
    try:
        with open(path, encoding="utf-8") as f:
            record = json.load(f)
    except (OSError, ValueError):
        return None
    return record if isinstance(record, dict) else None


def hash_inputs(record, previous=None, verify=False):
    """`record` (inputs with role and path only, as the library's *_record returns it) with each
    input's bytes, mtime_ns and sha256; the sha256 of `previous` (a record on disk) is reused for an
    input of the same path, size and modification time unless `verify`."""
    known = {}
    if previous and not verify:
        for i in previous.get("inputs", []):
            if isinstance(i, dict) and {"path", "bytes", "mtime_ns", "sha256"} <= set(i):
                known[(i["path"], i["bytes"], i["mtime_ns"])] = i["sha256"]
    inputs = []
    for i in record["inputs"]:
        st = os.stat(i["path"])
        key = (i["path"], st.st_size, st.st_mtime_ns)
        inputs.append(dict(i, bytes=st.st_size, mtime_ns=st.st_mtime_ns, sha256=known.get(key) or sha256(i["path"])))
    return dict(record, inputs=inputs)


def _flat(value, prefix=""):
    """{"a": {"b": 1}} -> {"a.b": 1}: settings compared key by key."""
    if isinstance(value, dict):
        out = {}
        for k, v in value.items():
            out.update(_flat(v, f"{prefix}{k}."))
        return out
    return {prefix[:-1]: value}


def _short(value):
    text = json.dumps(value)
    return text if len(text) <= 24 else text[:21] + "..."


def changes(expected, found):
    """What differs between the record a task would write and the one on disk, in words
    ("width 512 -> 1024", "input grid0.obj changed"); empty when the output was made the same way.
    The SIMD target is not compared: the outputs of a build do not depend on it beyond the last
    bits of some screen-space methods (BENCHMARKS.md), and a farm mixes CPUs."""
    if found is None:
        return ["no record of how it was made"]
    out = []
    version, found_version = expected["ao"]["version"], found.get("ao", {}).get("version")
    if version != found_version:
        out.append(f"ao {found_version} -> {version}")
    if expected.get("job") != found.get("job"):
        out.append(f"job {found.get('job')} -> {expected.get('job')}")
    new, old = _flat(expected.get("settings", {})), _flat(found.get("settings", {}))
    for key in sorted(set(new) | set(old)):
        if new.get(key) != old.get(key):
            out.append(f"{key} {_short(old.get(key))} -> {_short(new.get(key))}")
    found_inputs = [i for i in found.get("inputs", []) if isinstance(i, dict)]
    if [(i["role"], i["sha256"]) for i in expected["inputs"]] != [(i.get("role"), i.get("sha256")) for i in found_inputs]:
        before = {(i.get("role"), i.get("path")): i.get("sha256") for i in found_inputs}
        changed = [os.path.basename(i["path"]) for i in expected["inputs"] if before.get((i["role"], i["path"])) != i["sha256"]]
        out.append("input " + ", ".join(changed) + " changed" if changed else "the list of inputs changed")
    return out


def output_state(path):
    """"missing", "file" (a regular file, or a link to one) or what else is there ("a directory",
    "a FIFO", ...): only a regular file can be a complete output."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        return "missing"
    except OSError as e:
        return f"unreadable ({e.strerror})"
    if stat.S_ISREG(st.st_mode):
        return "file"
    kinds = [(stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISSOCK, "a socket"),
             (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device")]
    return next((name for test, name in kinds if test(st.st_mode)), "not a regular file")


def made(outputs, expected):
    """How the outputs of one task stand against `expected` (their record, inputs hashed):
    ("done", []) when every output is a regular file whose record matches it and names its size;
    ("missing", []) when an output is missing; ("blocked", [what]) when something that is not a
    regular file (a directory, a FIFO) has an output's name; ("changed", [what]) otherwise: made
    with other inputs or settings, by another ao, or without a record."""
    states = [(out, output_state(out)) for out in outputs]
    blocked = [f"{out} is {state}" for out, state in states if state not in ("missing", "file")]
    if blocked:
        return "blocked", blocked
    if any(state == "missing" for _, state in states):
        return "missing", []
    reasons = []
    for out in outputs:
        found = read(record_path(out))
        if found is None:
            why = ["no record of how it was made"]
        elif found.get("output", {}).get("bytes") != os.stat(out).st_size:
            why = [f"{os.path.basename(out)} is not the file its record describes"]
        else:
            why = changes(expected, found)
        reasons += [r for r in why if r not in reasons]
    return ("changed", reasons) if reasons else ("done", [])
