#!/usr/bin/env bash
# `kushner filter`: same seed, same numbers. timeseries.csv byte-identical on 1 and 2 OpenMP threads and on the
# Serial backend; summary.json identical apart from the "backend" and "timing" (wall times) fields; on a GPU, equal to a stated tolerance.
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
    # to 100 times what one ulp more of dt does on the host: an ill-conditioned filter (the car's EKF) amplifies
    # any rounding difference, and the host run with dt nudged measures by how much.
    local nudged=() previous=""
    for a in "$@"; do
      [ "$previous" = "--dt" ] && a=$(python3 -c "import math, sys; print(repr(math.nextafter(float(sys.argv[1]), 1.0)))" "$a")
      nudged+=("$a"); previous=$a
    done
    run_as "$name-serial-ulp" KUSHNER_BACKEND=serial -- "${nudged[@]}"
    python3 - "$work/$name-serial/timeseries.csv" "$work/$name-cuda/timeseries.csv" \
      "$work/$name-serial-ulp/timeseries.csv" <<'PY' || fail "$name: cuda differs from serial"
import math, sys
rows = [[l.rstrip("\n").split(",") for l in open(p) if not l.startswith("#")] for p in sys.argv[1:4]]
assert rows[0][0] == rows[1][0] == rows[2][0], "headers differ"
header = rows[0][0]
worst, where, failures = 0.0, None, []
for ra, rb, rc in zip(rows[0][1:], rows[1][1:], rows[2][1:]):
    assert ra[:2] == rb[:2] and ra[1] == rc[1], "rows differ in time or filter: %s %s %s" % (ra[:2], rb[:2], rc[:2])
    for column, a, b, c in zip(header[2:], map(float, ra[2:]), map(float, rb[2:]), map(float, rc[2:])):
        if math.isnan(a) and math.isnan(b):
            continue
        d = abs(a - b) / max(abs(a), abs(b), 1e-300)
        if d > worst:
            worst, where = d, (ra[0], ra[1], column, a, b, "one ulp of dt: %.3g" % (abs(a - c) / max(abs(a), 1e-300)))
        if not abs(a - b) <= 1e-8 * max(abs(a), abs(b)) + 100 * abs(a - c):
            failures.append((ra[0], ra[1], column, a, b, c))
print("largest relative difference cuda vs serial: %.3g at (t, filter, column, serial, cuda, ...) = %s" % (worst, where))
for f in failures[:5]:
    print("beyond 1e-8 and 100x one ulp of dt: (t, filter, column, serial, cuda, serial with dt + 1 ulp) =", f)
sys.exit(bool(failures))
PY
  fi
}

compare_runs sine --model sine --filters all --members 2000 --T 1 --dt 1e-2 --seed 7 --output-points 20
compare_runs cubic --model cubic-oscillator --filters all --members 1001 --T 0.5 --dt 5e-3 --seed 8 --output-points 10
compare_runs car --model car --filters all --members 500 --T 0.5 --dt 5e-3 --seed 9 --output-points 10
compare_runs terpolymer --model terpolymer --filters BILIN,MIXED,KBL,EKF --members 300 --T 0.2 --dt 1e-2 --seed 10
# Discrete time (steps of 1, no --dt): every discrete filter, the particle filter and the grid Bayes filter.
compare_runs clark --model clark-linear --filters all,EXACT --members 700 --particles 256 --T 15 --seed 11
compare_runs gauss-discrete --model linear-discrete --filters all --members 600 --particles 256 --T 15 --seed 12
