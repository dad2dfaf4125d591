#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""The verdict of bench/blender/compare.sh: medians over its rounds, and the CPU ratio at equal error.

    compare_summary.py ROWS.tsv

ROWS.tsv has one line per baked map (baker, setting, RMSE against its own baker's converged map, RMSE
against the other baker's, process CPU seconds), several per setting when compare.sh ran several
rounds. Prints the medians per setting and, for each Cycles setting, the cheapest ao setting (median
CPU s) whose error against ao's converged map is at most Cycles' error against Cycles' converged map,
with the ratio of their CPU seconds. bench/blender/addon_vs_cycles.py prints the same verdict (verdict()).
"""
import os
import statistics
import sys

LOAD_LIMIT = 2.0  # load average above which CPU seconds of the two bakers are not comparable


def load_refusal():
    """None if the 1-minute load average is at most LOAD_LIMIT or ALLOW_LOAD is set; else why not to run."""
    load = os.getloadavg()[0]
    if load <= LOAD_LIMIT or os.environ.get("ALLOW_LOAD"):
        return None
    return (f"load average {load:.2f} is above {LOAD_LIMIT:g}: CPU seconds are not comparable there (Blender's process inflates "
            "more than ao's); rerun on a quiet machine, or set ALLOW_LOAD=1 to run it anyway (the table is marked)")


def verdict(medians):
    """Lines saying, for each non-ao row of `medians` ({(baker, setting): {"own": RMSE, "cpu": s}}), the
    cheapest ao row whose own error is at most that row's, and the ratio of their CPU seconds."""
    ao = [(setting, m) for (baker, setting), m in medians.items() if baker == "ao"]
    lines = []
    for (baker, setting), m in medians.items():
        if baker == "ao":
            continue
        fits = [(a["cpu"], name, a) for name, a in ao if a["own"] <= m["own"]]
        if not fits:
            lines.append("at %s, %s (error %.5f): no ao setting of this run is as low" % (baker, setting, m["own"]))
            continue
        cpu, name, a = min(fits, key=lambda t: t[0])
        lines.append("at %s, %s (error %.5f): ao %s (%.5f), %.2f CPU s against %.2f: Cycles takes %.1fx the CPU" %
                     (baker, setting, m["own"], name, a["own"], cpu, m["cpu"], m["cpu"] / cpu))
    return lines


def main():
    rows = {}
    with open(sys.argv[1]) as f:
        for line in f:
            baker, setting, own, other, cpu = line.rstrip("\n").split("\t")
            r = rows.setdefault((baker, setting), {"own": [], "other": [], "cpu": []})
            r["own"].append(float(own))
            r["other"].append(float(other))
            r["cpu"].append(float(cpu))
    med = {k: {f: statistics.median(v) for f, v in r.items()} | {"n": len(r["cpu"])} for k, r in rows.items()}
    print("| baker | setting | RMSE vs own converged | RMSE vs other's converged | process CPU s (median) | runs |")
    print("|---|---|---:|---:|---:|---:|")
    for (baker, setting), m in med.items():
        print("| %s | %s | %.5f | %.5f | %.2f | %d |" % (baker, setting, m["own"], m["other"], m["cpu"], m["n"]))
    print()
    print("\n".join(verdict(med)))


if __name__ == "__main__":
    main()
