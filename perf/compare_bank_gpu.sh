#!/usr/bin/env bash
# The filter bank on the GPU through the command line against the same bank in JAX (issue 16 part 4):
#   kushner filter --model sine --filters EKF,SOF,QLF,KBL --members M --quiet (CUDA backend) at T = KUSHNER_BANK_T
# (0.25) and KUSHNER_BANK_T_SHORT (0.05), dt = 1e-3, with an output point per step (--output-points T / dt: at 0.25 and
# 0.05 the grid of the default 200 points): member-steps/s from the difference of summary.json's step_loop_s (and of
# the whole commands' wall times), perf/bank_jax.py the same way (fp64, lax.scan; without and with --metrics, the
# command line's work), and the device's copy bandwidth (JAX, x + 0 over 2 GiB: read + write) for the floor: ~421 B
# per member-step (truth x, dy; per filter m, P, status, scores, snapshots). At 0.25 and 0.05 the difference is ~15 ms
# on an H200, and the CLI's runs spread by +-10%: KUSHNER_BANK_T=2.5 KUSHNER_BANK_T_SHORT=0.5 measures it to 1%
# (perf/filter_bank.md, 2026-12-03).
#   perf/compare_bank_gpu.sh BUILD_DIR    (a CUDA build's kushner; prints one line per figure)
set -euo pipefail
build=${1:?usage: compare_bank_gpu.sh BUILD_DIR}
members=${KUSHNER_MEMBERS:-1000000}
reps=${KUSHNER_REPETITIONS:-3}
long=${KUSHNER_BANK_T:-0.25}
short=${KUSHNER_BANK_T_SHORT:-0.05}
work=$(mktemp -d)
trap 'kill "${sampler:-0}" 2> /dev/null || true; rm -rf "$work"' EXIT
nvidia-smi --query-gpu=name,power.limit,clocks.max.sm --format=csv,noheader
nvidia-smi --query-gpu=power.draw,clocks.sm --format=csv,noheader,nounits -lms 200 > "$work/power" 2> /dev/null < /dev/null &
sampler=$!
for rep in $(seq "$reps"); do
  for T in "$long" "$short"; do
    start=$(date +%s.%N)
    KUSHNER_BACKEND=cuda "$build/kushner" filter --model sine --filters EKF,SOF,QLF,KBL --members "$members" --T "$T" \
      --output-points "$(python3 -c "print(round($T / 1e-3))")" --seed "$rep" --out "$work/run-$rep-$T" --quiet \
      > /dev/null 2>&1
    end=$(date +%s.%N)
    echo "$T $(python3 -c "print($end - $start)")" >> "$work/wall-$rep"
    echo "run $rep T = $T: $(tail -1 "$work/wall-$rep") s" >&2
  done
done
kill "$sampler" 2>/dev/null || true
sort -t, -k1 -g "$work/power" | tail -1 | sed 's/^/largest power draw (W), SM clock (MHz) while kushner ran: /'
python3 - "$work" "$members" "$reps" "$long" "$short" <<'PY'
import json, statistics, sys
work, members, reps, long, short = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4], sys.argv[5]
steps = round(float(long) / 1e-3) - round(float(short) / 1e-3)
loop, wall = [], []
for rep in range(1, reps + 1):
    s = {T: json.load(open("%s/run-%d-%s/summary.json" % (work, rep, T)))["timing"] for T in (long, short)}
    loop.append(members * steps / (s[long]["step_loop_s"] - s[short]["step_loop_s"]))
    w = dict(line.split() for line in open("%s/wall-%d" % (work, rep)))
    wall.append(members * steps / (float(w[long]) - float(w[short])))
print("kushner CLI (CUDA): step loop %.4g member-steps/s (median of %s), whole command %.4g" %
      (statistics.median(loop), ["%.4g" % r for r in loop], statistics.median(wall)))
PY
python3 "$(dirname "$0")/bank_jax.py" --members "$members" --T "$long" --rate "$short" --repetitions "$reps"
# The same bank with the command line's statuses, score sums and moments at every step (its output steps here).
python3 "$(dirname "$0")/bank_jax.py" --members "$members" --T "$long" --rate "$short" --repetitions "$reps" --metrics
python3 - <<'PY'
import time, jax
jax.config.update("jax_enable_x64", True)
import jax.numpy as jnp
x = jnp.ones(1 << 28, dtype=jnp.float64)
f = jax.jit(lambda a: a + 0.0)
f(x).block_until_ready()
times = []
for _ in range(5):
    t = time.perf_counter(); f(x).block_until_ready(); times.append(time.perf_counter() - t)
bw = 2 * 8 * (1 << 28) / min(times)
print("copy bandwidth (JAX a + 0, 2 GiB read + write): %.3g GB/s; floor at 421 B per member-step: %.3g member-steps/s"
      % (bw / 1e9, bw / 421))
PY
