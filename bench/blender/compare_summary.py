#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""The verdict of bench/blender/compare.sh: medians over its rounds, and the CPU ratio at equal error.

    compare_summary.py ROWS.tsv

ROWS.tsv has one line per baked map (baker, setting, RMSE against its own baker's converged map, RMSE
against the other baker's, process CPU seconds), several per setting when compare.sh ran several
rounds. Prints the medians per setting and, for each Cycles setting, the cheapest ao setting (median
process CPU s) whose error against ao's converged map is at most Cycles' error against Cycles'
converged map, with the ratio of their CPU seconds: the comparison issue 39 decides by.
"""
import statistics
import sys


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
    ao = [(k[1], m) for k, m in med.items() if k[0] == "ao"]
    print()
    for (baker, setting), m in med.items():
        if baker == "ao":
            continue
        fits = [(a["cpu"], name, a) for name, a in ao if a["own"] <= m["own"]]
        if not fits:
            print("at %s, %s (error %.5f): no ao setting of this run is as low" % (baker, setting, m["own"]))
            continue
        cpu, name, a = min(fits, key=lambda t: t[0])
        print("at %s, %s (error %.5f): ao %s (%.5f), %.2f CPU s against %.2f: %.1fx less CPU" % (baker, setting, m["own"], name, a["own"], cpu, m["cpu"], m["cpu"] / cpu))


if __name__ == "__main__":
    main()
