#!/usr/bin/env bash
# Same seed, same numbers: timeseries.csv byte-identical on 1 and 2 OpenMP threads and on the serial backend (one host thread);
# summary.json identical apart from the "backend" and "timing" fields (timing: wall times, never the same twice).
set -euo pipefail
kushner=$1
source "$(dirname "$0")/lib.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The same command (hence the same --out) each time: the command is recorded in every file.
run_as() {  # run_as NAME ENV... -- ARGS...: run into $work/out, then keep it as $work/NAME
  local name=$1; shift
  local envs=()
  while [ "$1" != "--" ]; do envs+=("$1"); shift; done
  shift
  (cd "$work" && env "${envs[@]}" "$kushner" simulate "$@" --out out --quiet)
  mv "$work/out" "$work/$name"
}
compare_runs() {
  local name=$1; shift
  local backends
  backends=$(built_backends)
  run_as "$name-serial" KUSHNER_BACKEND=serial -- "$@"
  if grep -qw openmp <<<"$backends"; then  # a CUDA-only build has no OpenMP backend to compare
  run_as "$name-omp1" OMP_NUM_THREADS=1 KUSHNER_BACKEND=openmp -- "$@"
  run_as "$name-omp2" OMP_NUM_THREADS=2 KUSHNER_BACKEND=openmp -- "$@"
  for other in omp2 serial; do
    cmp "$work/$name-omp1/timeseries.csv" "$work/$name-$other/timeseries.csv" ||
      fail "$name: timeseries.csv differs between omp1 and $other"
    python3 - "$work/$name-omp1/summary.json" "$work/$name-$other/summary.json" <<'PY' || fail "$name: summary.json differs (omp1 vs $other)"
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
backend_a, backend_b = a.pop("backend"), b.pop("backend")
a.pop("timing"), b.pop("timing")
if a != b:
    sys.exit("summaries differ beyond the backend: %s" % sorted(k for k in a if a[k] != b.get(k)))
assert backend_a != backend_b or backend_a["name"] == "openmp"
PY
  done
  echo "ok: $name identical on omp1, omp2, serial"
  fi
  if grep -qw cuda <<<"$backends"; then
    run_as "$name-cuda" KUSHNER_BACKEND=cuda -- "$@"
    # FMA contraction and CUDA's libm round differently from glibc: equal to a stated relative tolerance.
    python3 - "$work/$name-serial/timeseries.csv" "$work/$name-cuda/timeseries.csv" <<'PY' || fail "$name: cuda differs from serial"
import sys
rows = [[l.rstrip("\n").split(",") for l in open(p) if not l.startswith("#")] for p in sys.argv[1:3]]
assert rows[0][0] == rows[1][0], "headers differ"
worst = 0.0
for ra, rb in zip(rows[0][1:], rows[1][1:]):
    for a, b in zip(map(float, ra), map(float, rb)):
        worst = max(worst, abs(a - b) / max(abs(a), abs(b), 1e-300))
print("largest relative difference cuda vs serial: %.3g" % worst)
sys.exit(worst > 1e-9)
PY
  fi
}

compare_runs sine --model sine --members 5000 --T 1 --dt 1e-2 --seed 7
compare_runs cubic --model cubic-oscillator --members 3001 --T 0.2 --dt 1e-3 --seed 8 --set 'x0_cov=1,0;0,1'
compare_runs clark --model clark-linear --members 4000 --T 30 --dt 1 --seed 9
