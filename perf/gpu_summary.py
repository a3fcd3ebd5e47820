#!/usr/bin/env python3
"""Summary of perf/run_gpu_benchmarks.sh's results: particle-steps/s of the PF step at every size, bytes
moved and the fraction of BM_StreamCopy's bandwidth, the ratio to PyTorch (eager and compiled) at
M = 1000, N = 65536, Kokkos vs Thrust resampling, and the test outcomes.

usage: gpu_summary.py OUT_DIR
"""
import json
import os
import statistics
import sys


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def iterations(data, prefix):
    if not data:
        return {}
    out = {}
    for r in data["benchmarks"]:
        if r.get("run_type") != "iteration" or not r["name"].startswith(prefix):
            continue
        out.setdefault(r["name"].split("/manual_time")[0].split("/repeats")[0], []).append(r)
    return out


def med(rows, key):
    values = [r[key] for r in rows if key in r]
    return (statistics.median(values), min(values), max(values), len(values)) if values else None


def main():
    out = sys.argv[1]
    gpu = open(os.path.join(out, "gpu.csv")).read().strip().splitlines()[-1] if os.path.exists(os.path.join(out, "gpu.csv")) else "?"
    print(f"device: {gpu}")
    pf = load(os.path.join(out, "bench_particle_filter.json"))
    steps = iterations(pf, "BM_ParticleFilterStep")
    copies = iterations(pf, "BM_StreamCopy")
    target = None
    for name, rows in steps.items():
        size = name.split("/", 1)[1]
        rate, lo, hi, n = med(rows, "particle_steps_per_s")
        gbs = med(rows, "GB_per_s")[0]
        copy = copies.get("BM_StreamCopy<SineModel>/" + size)
        frac = f", {gbs / med(copy, 'GB_per_s')[0]:.2f} of BM_StreamCopy ({med(copy, 'GB_per_s')[0]:.0f} GB/s)" if copy else ""
        res = med(rows, "resamples_per_member_step")
        print(f"PF step {size}: median {rate:.3g} particle-steps/s (n={n}, spread {lo:.3g}..{hi:.3g}); "
              f"32 B/particle-step = {gbs:.0f} GB/s{frac}; resamples/member-step {res[0]:.2g}")
        if size == "members:1000/particles:65536":
            target = rate
    for mode in ("eager", "compile"):
        t = load(os.path.join(out, f"torch_{mode}.json"))
        if t and target:
            print(f"PyTorch {mode} ({t['torch']}): median {t['median']:.3g} particle-steps/s (spread {t['min']:.3g}.."
                  f"{t['max']:.3g}); kushner / PyTorch {mode} = {target / t['median']:.3g}x")
        else:
            print(f"PyTorch {mode}: no result (see torch_{mode}.log)")
    if target:
        print(f"target: >= 6e10 particle-steps/s: {'met' if target >= 6e10 else 'NOT met'} ({target:.3g})")
    rs = load(os.path.join(out, "bench_resampling.json"))
    for name, rows in iterations(rs, "BM_Resample").items():
        m = med(rows, "particles_per_s")
        print(f"{name}: median {m[0]:.3g} particles/s (spread {m[1]:.3g}..{m[2]:.3g})")
    for t in ("test_resampling", "test_particle_filter", "test_particle_filter_references", "test_grid_filter"):
        r = load(os.path.join(out, f"{t}.json"))
        if r:
            print(f"{t}: {r['tests'] - r['failures']}/{r['tests']} passed")
        else:
            print(f"{t}: no result")


if __name__ == "__main__":
    main()
