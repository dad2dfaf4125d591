#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Side-by-side speed of two builds' ao_bench, alternating runs so both see the same machine load.

    bench/tools/compare_builds.py A/bench/ao_bench B/bench/ao_bench --pairs 5 --filter REGEX [-- more ao_bench arguments]

Every benchmark the filter selects (in A's list) runs on its own, A then B, `--pairs` times in
turn, so the two runs of a pair are seconds apart; the runs' order is A B A B ... per benchmark.
Reported per benchmark: the median time of A and of B (real time, and the CPU time Google
Benchmark reports), the ratio A / B of the medians of the pairs' ratios with their range, and the
ratio of the fastest runs (the least disturbed on a shared machine). Above 1: A is slower. The
runs' JSON is kept in --keep DIR when given.
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys


def run(binary, name, rest, keep, tag):
    args = [binary, "--benchmark_format=json", "--benchmark_filter=^" + re.escape(name) + "$"] + rest
    out = subprocess.run(args, check=True, capture_output=True, text=True).stdout
    if keep:
        with open(os.path.join(keep, tag + ".json"), "w") as f:
            f.write(out)
    for b in json.loads(out)["benchmarks"]:
        # With repetitions, the median aggregate stands for the run; without, the one result.
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "median":
            continue
        return b["real_time"], b["cpu_time"]
    raise RuntimeError(f"{binary}: no result for {name}")


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
    if o.keep:
        os.makedirs(o.keep, exist_ok=True)
    listed = subprocess.run([o.a, "--benchmark_list_tests", "--benchmark_filter=" + o.filter], check=True, capture_output=True, text=True).stdout
    names = [n for n in listed.split("\n") if n]
    print(f"{'benchmark':64s} {'A real':>9s} {'B real':>9s} {'A/B real':>9s} {'range':>12s} {'fastest':>8s} {'A/B cpu':>8s} {'range':>12s}")
    for i, name in enumerate(names):
        a, b = [], []
        for k in range(o.pairs):
            a.append(run(o.a, name, rest, o.keep, f"{i}a{k}"))
            b.append(run(o.b, name, rest, o.keep, f"{i}b{k}"))
        real = [x[0] / y[0] for x, y in zip(a, b)]
        cpu = [x[1] / y[1] for x, y in zip(a, b)]
        fastest = min(x[0] for x in a) / min(y[0] for y in b)
        print(f"{name:64s} {statistics.median(x[0] for x in a):9.3f} {statistics.median(y[0] for y in b):9.3f} {statistics.median(real):9.3f} "
              f"{min(real):5.3f}-{max(real):5.3f} {fastest:8.3f} {statistics.median(cpu):8.3f} {min(cpu):5.3f}-{max(cpu):5.3f}", flush=True)


if __name__ == "__main__":
    main()
