#!/usr/bin/env bash
# The filter bank through the command line against the same bank in NumPy (perf/bank_numpy.py), timed in the
# same run (issue 16 part 4):
#   kushner filter --model sine --filters EKF,SOF,QLF,KBL --members M --quiet   at T = 0.25 and T = 0.05
# (dt = 1e-3): the difference of the two wall times over the difference of member-steps gives member-steps/s
# with start-up, allocation, pre-pass and output writing cancelled out; the NumPy bank (truth + the same four
# filters, vectorized over members, one core, no metrics) is timed the same way. Also the truth step alone,
# `kushner simulate` of sine, cubic-oscillator and cubic-sensor, by the same difference.
#   perf/compare_bank_numpy.sh [build-dir]        (default: build; Release, -march=native)
# Environment: KUSHNER_REPETITIONS (default 3; medians are printed), KUSHNER_MEMBERS (default 1000000),
# OMP_NUM_THREADS (default 2). Prints the load before and after (the machine is shared), every run's seconds,
# medians, the kushner/NumPy ratio, the truth steps per member-step, and the bank's bytes per member-step over a
# measured copy bandwidth (the floor).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
kushner=$build/kushner
[ -x "$kushner" ] || { echo "no $kushner: build it first (cmake --build $build --target kushner)" >&2; exit 2; }
python=python3
"$python" -c "import numpy" 2>/dev/null || python=/usr/bin/python3  # Debian's python3-numpy
reps=${KUSHNER_REPETITIONS:-3}
members=${KUSHNER_MEMBERS:-1000000}
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-2} OMP_PROC_BIND=${OMP_PROC_BIND:-false} KUSHNER_BACKEND=${KUSHNER_BACKEND:-openmp}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
T_long=0.25 T_short=0.05 dt=1e-3

echo "kushner $("$kushner" --version | head -n 1); git $(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo '?')"
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg); compilers running: $(pgrep -c cc1plus || true); OMP_NUM_THREADS=$OMP_NUM_THREADS"

# seconds CMD...: wall seconds of one command (its output discarded)
seconds() {
  local start end
  start=$(date +%s.%N)
  "$@" > /dev/null
  end=$(date +%s.%N)
  echo "$end - $start" | bc -l
}

: > "$work/times"
for rep in $(seq "$reps"); do
  for T in $T_long $T_short; do
    s=$(seconds "$kushner" filter --model sine --filters EKF,SOF,QLF,KBL --members "$members" --T $T --dt $dt \
          --seed $rep --quiet --out "$work/bank-$T")
    loop=$("$python" -c 'import json,sys; print(json.load(open(sys.argv[1]))["timing"]["step_loop_s"])' \
             "$work/bank-$T/summary.json" 2>/dev/null || echo nan)
    echo "bank $rep $T $s $loop" >> "$work/times"
    for model in sine cubic-oscillator cubic-sensor; do
      s=$(seconds "$kushner" simulate --model $model --members "$members" --T $T --dt $dt --seed $rep --quiet \
            --out "$work/sim-$model-$T")
      loop=$("$python" -c 'import json,sys; print(json.load(open(sys.argv[1]))["timing"]["step_loop_s"])' \
               "$work/sim-$model-$T/summary.json" 2>/dev/null || echo nan)
      echo "truth-$model $rep $T $s $loop" >> "$work/times"
    done
  done
  OMP_NUM_THREADS=1 "$python" "$here/perf/bank_numpy.py" --members "$members" --T $T_long --rate $T_short --dt $dt \
    --seed $rep > "$work/numpy-$rep.json"
done
"$python" "$here/perf/copy_bandwidth.py" > "$work/copy.json"
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg); compilers running: $(pgrep -c cc1plus || true)"

"$python" - "$work" "$reps" "$members" "$T_long" "$T_short" "$dt" <<'PY'
import glob, json, statistics, sys
work, reps, members, T_long, T_short, dt = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), *map(float, sys.argv[4:])
steps = round(T_long / dt) - round(T_short / dt)
runs = {}
for line in open(work + "/times"):
    what, rep, T, s, loop = line.split()
    runs.setdefault(what, {}).setdefault(int(rep), {})[float(T)] = (float(s), float(loop))
def rates(what, i=0):  # i = 0: whole commands' wall times; 1: summary.json's step_loop_s
    return [members * steps / (r[T_long][i] - r[T_short][i]) for r in runs[what].values()]
def med(xs):
    return statistics.median(xs)
def show(label, xs):
    print(f"{label}: median {med(xs):.3g} member-steps/s (n={len(xs)}, spread {min(xs):.3g}..{max(xs):.3g})")
print(f"M = {members}, dt = {dt}, T = {T_long} minus T = {T_short} ({steps} steps), wall time of whole commands")
bank = rates("bank")
for rep, r in sorted(runs["bank"].items()):
    print(f"  kushner filter rep {rep}: T={T_long}: {r[T_long][0]:.3f} s (step loop {r[T_long][1]:.3f} s), "
          f"T={T_short}: {r[T_short][0]:.3f} s (step loop {r[T_short][1]:.3f} s)")
show("kushner filter sine EKF,SOF,QLF,KBL (CLI)", bank)
show("  the same from summary.json's step_loop_s", rates("bank", 1))
numpy = [json.load(open(f)) for f in sorted(glob.glob(work + "/numpy-*.json"))]
np_rates = [n["member_steps_per_s"][0] for n in numpy]
for n in numpy:
    print(f"  NumPy rep: T={T_long}: {n['step_loop_s'][0]:.3f} s, T={T_short}: {n['step_loop_short_s'][0]:.3f} s")
show(f"NumPy {numpy[0]['numpy']} bank (1 core)", np_rates)
print(f"kushner / NumPy = {med(bank) / med(np_rates):.3g}x (medians)")
truth = {m: rates("truth-" + m) for m in ("sine", "cubic-oscillator", "cubic-sensor")}
truth_loops = {m: rates("truth-" + m, 1) for m in truth}
for m, xs in truth.items():
    show(f"kushner simulate {m} (truth step)", xs)
    show("  the same from summary.json's step_loop_s", truth_loops[m])
for m in ("cubic-oscillator", "cubic-sensor"):
    print(f"truth step per member-step, {m} / sine = {med(truth['sine']) / med(truth[m]):.3g}x the time "
          f"(step loops: {med(truth_loops['sine']) / med(truth_loops[m]):.3g}x)")
copy = json.load(open(work + "/copy.json"))
# Bytes per member-step of the bank: truth x (r+w), dy (w, then r); per filter m, P (r+w each), status (r),
# the score sums (squared error, nees, nees points: r+w), the snapshot at output steps (2 doubles, w).
per_filter = 8 * 2 + 8 * 2 + 1 + 3 * 16 + 2 * 8
bytes_per = 8 * 2 + 8 * 2 + 1 + 4 * per_filter
print(f"copy bandwidth {copy['GB_per_s']:.3g} GB/s ({copy['note']}); bank traffic ~{bytes_per} B per member-step "
      f"-> floor ~{copy['GB_per_s'] * 1e9 / bytes_per:.3g} member-steps/s for a step at a time (from 4096 members "
      f"the host takes steps 16 at a time, FilterBank::start_segment, moving these bytes once per segment)")
PY
