#!/usr/bin/env bash
# MPI on the CPU: 2 ranks x 1 thread against 1 rank x 2 threads (and 1 x 1 for scale), the same command, wall time
# of the whole command, median of KUSHNER_REPETITIONS (default 5) runs each, interleaved so that a busy second core
# hurts every configuration alike. Also checks that the outputs are the same bytes (summary.json's backend aside).
#   perf/run_mpi_cpu.sh build/kushner [kushner args...]
# Default workload: sine, EKF, SOF, QLF, KBL and a 1024-particle PF, M = 2048 (8 blocks: 4 per rank), T = 1, dt = 2e-3.
set -euo pipefail
kushner=$(realpath "$1"); shift
args=("$@")
[ ${#args[@]} -gt 0 ] || args=(filter --model sine --filters EKF,SOF,QLF,KBL,PF --members 2048 --particles 1024 --T 1
                               --dt 2e-3 --seed 1)
repetitions=${KUSHNER_REPETITIONS:-5}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export OMP_PROC_BIND=false OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
run() {  # run NAME THREADS COMMAND...: writes $work/NAME/out, appends the wall time to $work/NAME.times
  local name=$1 threads=$2; shift 2
  local t0 t1
  mkdir -p "$work/$name"
  t0=$(date +%s.%N)
  (cd "$work/$name" && OMP_NUM_THREADS=$threads "$@" "$kushner" "${args[@]}" --quiet --out out >/dev/null)
  t1=$(date +%s.%N)
  echo "$t1 - $t0" | bc >> "$work/$name.times"
}
for ((i = 0; i < repetitions; ++i)); do
  run r1t2 2 env
  run r2t1 1 mpirun -q --bind-to none -np 2
  run r1t1 1 env
done
python3 - "$work" "$repetitions" "${args[*]}" <<'PY'
import statistics, sys
work, reps, command = sys.argv[1], sys.argv[2], sys.argv[3]
t = {n: sorted(float(x) for x in open(f"{work}/{n}.times")) for n in ("r1t2", "r2t1", "r1t1")}
m = {n: statistics.median(v) for n, v in t.items()}
print(f"kushner {command}  ({reps} runs each, wall time of the command)")
for n, label in (("r1t1", "1 rank  x 1 thread "), ("r1t2", "1 rank  x 2 threads"), ("r2t1", "2 ranks x 1 thread ")):
    print(f"  {label}: median {m[n]:.2f} s (min {t[n][0]:.2f}, max {t[n][-1]:.2f})")
print(f"  2 ranks x 1 thread / 1 rank x 2 threads = {m['r2t1'] / m['r1t2']:.3f}")
PY
for f in $(cd "$work/r1t2/out" && ls); do
  if [ "$f" = summary.json ]; then
    cmp -s <(sed '/^  "backend": {/,/^  },\{0,1\}$/d' "$work/r1t2/out/$f") <(sed '/^  "backend": {/,/^  },\{0,1\}$/d' "$work/r2t1/out/$f")
  else
    cmp -s "$work/r1t2/out/$f" "$work/r2t1/out/$f"
  fi || { echo "FAIL: $f differs between 1 rank x 2 threads and 2 ranks x 1 thread" >&2; exit 1; }
done
echo "  outputs of 1 rank x 2 threads and 2 ranks x 1 thread: the same bytes (summary.json's backend aside)"
