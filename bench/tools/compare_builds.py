#!/usr/bin/python3
"""Side-by-side speed of two builds' ao_bench, alternating runs so both see the same machine load.

    bench/tools/compare_builds.py A/bench/ao_bench B/bench/ao_bench --pairs 5 --filter REGEX [-- more ao_bench arguments]

Runs A, B, A, B, ... (`--pairs` of each), every run with the same benchmark filter and arguments,
and reports per benchmark the ratio A / B of its time (real time, and the CPU time Google Benchmark
reports), taken within each pair and summarised as the median and the range over the pairs.
A ratio above 1 means A is slower. The runs' own output is kept in --keep DIR when given.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys


def run(binary, args, keep, tag):
    out = subprocess.run([binary, "--benchmark_format=json"] + args, check=True, capture_output=True, text=True).stdout
    if keep:
        with open(os.path.join(keep, tag + ".json"), "w") as f:
            f.write(out)
    times = {}
    for b in json.loads(out)["benchmarks"]:
        # With repetitions, the median aggregate stands for the run; without, the one result.
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "median":
            continue
        name = b.get("run_name", b["name"])
        if b.get("run_type") == "iteration" and name in times:
            continue
        times[name] = (b["real_time"], b["cpu_time"])
    return times


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("a", help="ao_bench of build A (the one measured)")
    p.add_argument("b", help="ao_bench of build B (the baseline)")
    p.add_argument("--pairs", type=int, default=5)
    p.add_argument("--filter", default=".")
    p.add_argument("--keep", help="directory for every run's JSON")
    argv = sys.argv[1:]
    rest = argv[argv.index("--") + 1:] if "--" in argv else []
    o = p.parse_args(argv[:argv.index("--")] if "--" in argv else argv)
    args = ["--benchmark_filter=" + o.filter] + rest
    if o.keep:
        os.makedirs(o.keep, exist_ok=True)
    ratios = {}
    for k in range(o.pairs):
        ta = run(o.a, args, o.keep, f"a{k}")
        tb = run(o.b, args, o.keep, f"b{k}")
        for name in ta:
            if name in tb:
                r = ratios.setdefault(name, ([], [], [], []))
                r[0].append(ta[name][0] / tb[name][0])
                r[1].append(ta[name][1] / tb[name][1])
                r[2].append(ta[name][0])
                r[3].append(tb[name][0])
        print(f"pair {k + 1}/{o.pairs} done", file=sys.stderr)
    print(f"{'benchmark':60s} {'A real':>9s} {'B real':>9s} {'A/B real':>9s} {'range':>13s} {'A/B cpu':>9s} {'range':>13s}")
    for name, (real, cpu, a, b) in ratios.items():
        print(f"{name:60s} {statistics.median(a):9.3f} {statistics.median(b):9.3f} {statistics.median(real):9.3f} "
              f"{min(real):6.3f}-{max(real):5.3f} {statistics.median(cpu):9.3f} {min(cpu):6.3f}-{max(cpu):5.3f}")


if __name__ == "__main__":
    main()
