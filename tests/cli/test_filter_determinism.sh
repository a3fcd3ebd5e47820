#!/usr/bin/env bash
# `kushner filter`: same seed, same numbers. timeseries.csv byte-identical on 1 and 2 OpenMP threads and on the
# serial backend (one host thread); summary.json identical apart from the "backend" and "timing" (wall times) fields; on a GPU, equal to a stated tolerance.
set -euo pipefail
kushner=$1
source "$(dirname "$0")/lib.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

run_as() {  # run_as NAME ENV... -- ARGS...: run into $work/out (the same --out each time: it is in the files)
  local name=$1; shift
  local envs=()
  while [ "$1" != "--" ]; do envs+=("$1"); shift; done
  shift
  (cd "$work" && env "${envs[@]}" "$kushner" filter "$@" --out out --quiet)
  mv "$work/out" "$work/$name"
}
compare_runs() {
  local name=$1; shift
  local backends
  backends=$(built_backends)
  run_as "$name-serial" KUSHNER_BACKEND=serial -- "$@"
  if grep -qw openmp <<<"$backends"; then
    run_as "$name-omp1" OMP_NUM_THREADS=1 KUSHNER_BACKEND=openmp -- "$@"
    run_as "$name-omp2" OMP_NUM_THREADS=2 KUSHNER_BACKEND=openmp -- "$@"
    for other in omp1 omp2; do
      cmp "$work/$name-serial/timeseries.csv" "$work/$name-$other/timeseries.csv" ||
        fail "$name: timeseries.csv differs between serial and $other"
      python3 - "$work/$name-serial/summary.json" "$work/$name-$other/summary.json" <<'PY' || fail "$name: summary.json differs (serial vs $other)"
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
a.pop("backend"), b.pop("backend")
a.pop("timing"), b.pop("timing")
if a != b:
    sys.exit("summaries differ beyond the backend: %s" % sorted(k for k in a if a[k] != b.get(k)))
PY
    done
    echo "ok: $name identical on serial, omp1, omp2"
  fi
  if grep -qw cuda <<<"$backends"; then
    run_as "$name-cuda" KUSHNER_BACKEND=cuda -- "$@"
    # FMA contraction and CUDA's libm round differently from glibc. Each number must agree to 1e-8 relative, or
    # to 100 times what a rounding difference does on the host: an ill-conditioned filter (the car's EKF and UKF,
    # whose NEES is ~4e5) amplifies any. The host runs with dt nudged by -2, -1, +1 and +2 ulps measure by how much;
    # one nudge alone is a single draw of that amplification and can come out small at one output time (the car's
    # UKF at t = 0.45 on an H100: 1.9e-5 after +1 ulp, 1.9e-3 between the backends, beyond 100x; measured).
    local ulp_runs=() nudges=()
    [[ " $* " != *" --dt "* ]] || nudges=(-2 -1 1 2)  # discrete time: no dt, the numbers must agree to 1e-8
    for ulps in "${nudges[@]}"; do
      local nudged=() previous=""
      for a in "$@"; do
        [ "$previous" = "--dt" ] && a=$(python3 -c "import math, sys
x, k = float(sys.argv[1]), int(sys.argv[2])
for _ in range(abs(k)): x = math.nextafter(x, math.copysign(math.inf, k))
print(repr(x))" "$a" "$ulps")
        nudged+=("$a"); previous=$a
      done
      run_as "$name-serial-ulp$ulps" KUSHNER_BACKEND=serial -- "${nudged[@]}"
      ulp_runs+=("$work/$name-serial-ulp$ulps/timeseries.csv")
    done
    python3 - "$work/$name-serial/timeseries.csv" "$work/$name-cuda/timeseries.csv" "${ulp_runs[@]}" <<'PY' ||
import math, sys
rows = [[l.rstrip("\n").split(",") for l in open(p) if not l.startswith("#")] for p in sys.argv[1:]]
serial, cuda, nudged = rows[0], rows[1], rows[2:]
assert all(r[0] == serial[0] for r in rows), "headers differ"
header = serial[0]
worst, where, failures = 0.0, None, []
for i, (ra, rb) in enumerate(zip(serial[1:], cuda[1:])):
    # A nudged run's output times are nudged too: its rows must name the same filter.
    assert ra[:2] == rb[:2] and all(ra[1] == n[1 + i][1] for n in nudged), "rows differ in time or filter at %s" % ra[:2]
    for j, column in enumerate(header[2:]):
        a, b = float(ra[2 + j]), float(rb[2 + j])
        if math.isnan(a) and math.isnan(b):
            continue
        rounding = max((abs(a - float(n[1 + i][2 + j])) for n in nudged), default=0.0)
        d = abs(a - b) / max(abs(a), abs(b), 1e-300)
        if d > worst:
            worst, where = d, (ra[0], ra[1], column, a, b, "nudged dt: %.3g" % (rounding / max(abs(a), 1e-300)))
        if not abs(a - b) <= 1e-8 * max(abs(a), abs(b)) + 100 * rounding:
            failures.append((ra[0], ra[1], column, a, b, rounding))
print("largest relative difference cuda vs serial: %.3g at (t, filter, column, serial, cuda, ...) = %s" % (worst, where))
for f in failures[:5]:
    print("beyond 1e-8 and 100x the nudged runs: (t, filter, column, serial, cuda, largest change by a nudge) =", f)
sys.exit(bool(failures))
PY
      fail "$name: cuda differs from serial"
  fi
}

compare_runs sine --model sine --filters all --members 2000 --T 1 --dt 1e-2 --seed 7 --output-points 20
# 4096 members and more take segments of 16 steps (run_filters): the host's chunk form on Serial and OpenMP, the team
# form on a GPU; output steps every 5 of the 50 steps fall inside segments and at the end of the last, short one.
compare_runs sine-segments --model sine --filters EKF,SOF,QLF,KBL --members 5000 --T 0.5 --dt 1e-2 --seed 13 \
  --output-points 10
compare_runs cubic --model cubic-oscillator --filters all --members 1001 --T 0.5 --dt 5e-3 --seed 8 --output-points 10
compare_runs car --model car --filters all --members 500 --T 0.5 --dt 5e-3 --seed 9 --output-points 10
compare_runs terpolymer --model terpolymer --filters BILIN,MIXED,KBL,EKF --members 300 --T 0.2 --dt 1e-2 --seed 10
# Discrete time (steps of 1, no --dt): every discrete filter, the particle filter and the grid Bayes filter.
# clark-linear's measurement noise is uniform (rho_v = 0): a member's particles inside its bound weigh exactly the
# same, and when 128 of 256 are inside, the ESS (128) sits on the default resampling threshold (0.5 x 256) within
# rounding, so a GPU and the host can decide differently: on an H200, KF's rmse_ref_se 4.6e-5 apart at t = 3 with
# 0.5, 2e-13 at most with 0.501 (a threshold times N that no whole number of equal weights reaches).
compare_runs clark --model clark-linear --filters all,EXACT --members 700 --particles 256 --ess-threshold 0.501 --T 15 \
  --seed 11
compare_runs gauss-discrete --model linear-discrete --filters all --members 600 --particles 256 --T 15 --seed 12
