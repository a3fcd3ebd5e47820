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


def report_sizes(out, source):
    """Prints every PF step size in one benchmark file; returns the rates at M = 1000, N = 65536 with
    resampling: {"step": one step per call, "step_pair": ParticleFilterBank::step_pair}."""
    pf = load(os.path.join(out, source))
    steps = iterations(pf, "BM_ParticleFilterStep")
    copies = iterations(pf, "BM_StreamCopy")
    target = {}
    if steps:
        print(f"-- {source} ({pf['context'].get('backend', '?')})")
    for name, rows in steps.items():
        size = name.split("/", 1)[1]
        rate, lo, hi, n = med(rows, "particle_steps_per_s")
        gbs = med(rows, "GB_per_s")[0]
        nbytes = med(rows, "bytes_per_particle_step")[0]  # 16 for a fused step pair (8 in fp32)
        copy = copies.get("BM_StreamCopy<SineModel>/" + size.split("/per_thread")[0])
        frac = ""
        if copy:
            bw = med(copy, "GB_per_s")[0]
            frac = f", {gbs / bw:.2f} of BM_StreamCopy ({bw:.0f} GB/s, floor {bw / (nbytes * 1e-9):.3g} particle-steps/s)"
        res = med(rows, "resamples_per_member_step")
        print(f"PF step {size}: median {rate:.3g} particle-steps/s (n={n}, spread {lo:.3g}..{hi:.3g}); "
              f"{nbytes:.0f} B/particle-step = {gbs:.0f} GB/s{frac}; resamples/member-step {res[0]:.2g}")
        for calls, key in (("1", "step"), ("2", "step_pair")):
            for code, precision in (("0", ""), ("1", " mixed"), ("2", " fp32")):
                if size == f"members:1000/particles:65536/per_thread:0/resample:1/steps:{calls}/precision:{code}":
                    target[key + precision] = rate
    return target


def report_power(out):
    """Median power draw and SM clock while the kushner step ran (power.csv, sampled by the compare phase)."""
    try:
        rows = [line.split(", ") for line in open(os.path.join(out, "power.csv")) if line.count(",") == 4]
        rows = [r for r in rows if float(r[0]) > 0.5 * float(r[1])]  # busy samples only
    except (OSError, ValueError):
        return
    if rows:
        throttle = sorted({r[4].strip() for r in rows})
        print(f"while kushner ran ({len(rows)} samples): power median {statistics.median(float(r[0]) for r in rows):.0f} W "
              f"of {rows[0][1]} W, SM clock median {statistics.median(float(r[2]) for r in rows):.0f} MHz of "
              f"{rows[0][3]} MHz, throttle reasons {' '.join(throttle)} (0x4: software power cap)")


def report_other(out, stem, label, version_key, target):
    """Another implementation's rates ({stem}.json, printed by perf/pf_torch.py or perf/pf_jax.py) and kushner's
    rates over it."""
    t = load(os.path.join(out, f"{stem}.json"))
    if not (t and target):
        print(f"{label}: no result (see {stem}.log)")
        return
    ratios = ", ".join(f"kushner {key} / {label} = {rate / t['median']:.3g}x" for key, rate in target.items())
    print(f"{label} ({t[version_key]}): median {t['median']:.3g} particle-steps/s (spread {t['min']:.3g}.."
          f"{t['max']:.3g}); {ratios}")


def main():
    out = sys.argv[1]
    gpu_csv = os.path.join(out, "gpu.csv")
    print("device: " + (open(gpu_csv).read().strip().splitlines()[-1] if os.path.exists(gpu_csv) else "?"))
    target = report_sizes(out, "bench_compare.json")
    report_power(out)
    print("-- PyTorch, same call as bench_compare.json")
    for mode in ("eager", "compile"):
        report_other(out, f"torch_{mode}", f"PyTorch {mode}", "torch", target)
    print("-- JAX (propagate, weight, moments; no resampling), same call")
    for dtype in ("float64", "float32"):
        report_other(out, f"jax_{dtype}", f"JAX {dtype}", "jax", target)
    print("-- the command line (kushner filter --model sine --filters PF, M = 1000, N = 65536, 1000 steps), same call")
    for precision, key in (("fp64", "step"), ("mixed", "step mixed"), ("fp32", "step fp32")):
        rates = {}
        for pairs, name in (("auto", f"cli_{precision}"), ("never", f"cli_{precision}_single")):
            c = load(os.path.join(out, f"{name}.json"))
            if c and "timing" in c:
                rate = rates[pairs] = c["timing"]["particle_steps_per_s"]
                versus = f", {rate / target[key]:.3f} of the benchmark's {key}" if key in target else ""
                used = c["filters"]["PF"]["estimator"].get("step_pairs", "?")
                print(f"CLI {precision}, --step-pairs {pairs} ({used}): step loop {c['timing']['step_loop_s']:.3g} s, "
                      f"{rate:.3g} particle-steps/s{versus}")
            else:
                print(f"CLI {precision}, --step-pairs {pairs}: no result (see {name}.log)")
        if len(rates) == 2:
            print(f"CLI {precision}: step pairs / single steps = {rates['auto'] / rates['never']:.3f}")
    for key, rate in target.items():
        print(f"target >= 6e10 particle-steps/s at M=1000, N=65536 ({key}): {'met' if rate >= 6e10 else 'NOT met'} ({rate:.3g})")
    # Issue 16's precision targets, by the faster of step and step_pair.
    jax32 = load(os.path.join(out, "jax_float32.json"))
    for precision, floor in (("mixed", 1.2e11), ("fp32", 2.9e11)):
        rates = [r for k, r in target.items() if k.endswith(" " + precision)]
        if rates:
            best = max(rates)
            extra = f", {best / jax32['median']:.2f}x JAX float32" if jax32 and precision == "fp32" else ""
            print(f"issue 16: {precision} >= {floor:.2g}: {'met' if best >= floor else 'NOT met'} ({best:.3g}{extra})")
    report_sizes(out, "bench_particle_filter.json")
    rs = load(os.path.join(out, "bench_resampling.json"))
    for name, rows in iterations(rs, "BM_Resample").items():
        m = med(rows, "particles_per_s")
        print(f"{name}: median {m[0]:.3g} particles/s (spread {m[1]:.3g}..{m[2]:.3g})")
    for t in ("test_particle_random", "test_resampling", "test_particle_filter", "test_particle_filter_references",
              "test_grid_filter", "test_particle_snapshot", "test_filter_consistency"):
        r = load(os.path.join(out, f"{t}.json"))
        print(f"{t}: {r['tests'] - r['failures']}/{r['tests']} passed" if r else f"{t}: no result")


if __name__ == "__main__":
    main()
