#!/usr/bin/env python3
"""Medians (over repetitions) of two benchmarks in one Google Benchmark JSON file, and their ratio.

usage: perf/ratio.py results.json BM_A BM_B [counter]
Prints "A/B = <r>x (median of <n>)" using real_time (or the counter, e.g. member_steps_per_s, if given).
"""
import json
import statistics
import sys


def samples(runs, name, counter):
    values = [r[counter] if counter else r["real_time"] for r in runs
              if r.get("run_type") == "iteration" and r["name"].split("/repeats")[0] == name]
    if not values:
        sys.exit(f"ratio.py: no iterations named {name!r}; have: {sorted({r['name'] for r in runs})}")
    return values


def main():
    if len(sys.argv) not in (4, 5):
        sys.exit(__doc__)
    data = json.load(open(sys.argv[1]))
    counter = sys.argv[4] if len(sys.argv) == 5 else None
    a, b = samples(data["benchmarks"], sys.argv[2], counter), samples(data["benchmarks"], sys.argv[3], counter)
    ma, mb = statistics.median(a), statistics.median(b)
    what = counter or "real_time"
    print(f"{sys.argv[2]}: median {what} {ma:.6g} (n={len(a)}, spread {min(a):.4g}..{max(a):.4g})")
    print(f"{sys.argv[3]}: median {what} {mb:.6g} (n={len(b)}, spread {min(b):.4g}..{max(b):.4g})")
    print(f"A/B = {ma / mb:.4g}x (median of {min(len(a), len(b))}; context: {data['context'].get('backend', '?')})")


if __name__ == "__main__":
    main()
