#!/usr/bin/env bash
# Issue 15's GPU figures in one device call (phases: build, tests, filters, control, reproduce; `run` = the last four):
#   build      build-cuda-discrete/: CUDA + OpenMP + Serial, kushner and the discrete-time tests
#   tests      test_discrete_filters on the GPU (its default space), test_discrete_control
#   filters    `kushner filter` on clark-linear, linear-discrete and the discrete model file duffing_discrete.toml,
#              every discrete filter, PF and EXACT, CUDA against Serial (largest relative difference per file, and
#              per filter), and clark-quintic (KF-NOM, MOM-NOM along the nominal path)
#   control    `kushner control` on clark-linear (with MOM-SPEC) and clark-quintic (the perturbation loop LQR-NOM),
#              CUDA against Serial
#   reproduce  `reproduce clark-table-2.1` at 20000 members and clark-table-3.1 on the GPU, timed
#   OUT=<dir> KUSHNER_PHASES="build run" perf/run_discrete_gpu.sh
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=${OUT:-$here/discrete-gpu-out}
mkdir -p "$out"
build=$here/build-cuda-discrete
phases=" ${KUSHNER_PHASES:-build run} "
phases=${phases/ run / tests filters control reproduce }
want() { [[ "$phases" == *" $1 "* ]]; }
export PATH=/usr/local/cuda/bin:$PATH OMP_PROC_BIND=false
status=0
log() { echo "== $(date +%T) $*" | tee -a "$out/steps.log"; }
nvidia-smi --query-gpu=name,memory.total,power.limit,clocks.max.sm,driver_version --format=csv > "$out/gpu.csv" 2>&1

if want build; then
  log "configure"
  cmake -C "$here/perf/gpu_machine.cmake" -S "$here" -B "$build" \
    -DCMAKE_BUILD_TYPE=Release -DKUSHNER_ENABLE_CUDA=ON -DKUSHNER_ENABLE_OPENMP=ON \
    -DKUSHNER_ENABLE_SERIAL=ON -DKUSHNER_ENABLE_MPI=OFF > "$out/configure.log" 2>&1 || { tail -20 "$out/configure.log"; exit 1; }
  log "common libraries"
  cmake --build "$build" -j16 --target kushner_test_main kushner_driver > "$out/build_common.log" 2>&1 ||
    { grep -B2 -A10 -m3 "error" "$out/build_common.log"; exit 1; }
  pids=()
  for t in kushner test_discrete_filters test_discrete_control; do
    cmake --build "$build" -j8 --target "$t" > "$out/build_$t.log" 2>&1 &
    pids+=($!)
  done
  for p in "${pids[@]}"; do wait "$p" || status=1; done
  grep -h -B2 -A10 -m3 " error" "$out"/build_*.log | head -40
  log "built (status $status)"
fi

if want tests; then
  log "test_discrete_filters (CUDA default space)"
  "$build/tests/test_discrete_filters" > "$out/test_discrete_filters.log" 2>&1 || status=1
  grep -E "OK|FAILED|PASSED|MOM order|PF N|squared error" "$out/test_discrete_filters.log"
  log "test_discrete_control (host)"
  "$build/tests/test_discrete_control" > "$out/test_discrete_control.log" 2>&1 || status=1
  grep -E "OK \]|FAILED|PASSED|J =|D =" "$out/test_discrete_control.log"
fi

if want filters; then
  for run in "clark --model clark-linear --filters all,EXACT --members 500 --particles 1024 --T 50 --seed 11" \
             "gauss --model linear-discrete --filters all --members 2000 --particles 1024 --T 50 --seed 12" \
             "gauss-exact --model linear-discrete --filters KF,EXACT --members 100 --T 20 --seed 12" \
             "duffing --model-file $here/models/examples/duffing_discrete.toml --filters all,EXACT --members 100 --particles 1024 --T 30 --seed 14" \
             "quintic --model clark-quintic --filters all,EXACT --members 1000 --particles 1024 --T 50 --seed 13 --set bound_w=0.3"; do
    set -- $run
    name=$1; shift
    log "filter $name: cuda against serial"
    KUSHNER_BACKEND=cuda "$build/kushner" filter "$@" --out "$out/$name-cuda" --quiet > "$out/$name-cuda.log" 2>&1 || status=1
    KUSHNER_BACKEND=serial "$build/kushner" filter "$@" --out "$out/$name-serial" --quiet > "$out/$name-serial.log" 2>&1 ||
      status=1
    python3 - "$out/$name-cuda/timeseries.csv" "$out/$name-serial/timeseries.csv" <<'PY' | tee -a "$out/steps.log"
import math, sys
rows = [[l.rstrip("\n").split(",") for l in open(p) if not l.startswith("#")] for p in sys.argv[1:3]]
# Against the truth (rmse_truth, nees) a filter depends on the truths and itself only; rmse_ref also on the particle
# filter, whose resampling can pick another particle where two cumulative weights differ in their last bits.
header, worst = rows[0][0], {}
for ra, rb in zip(rows[0][1:], rows[1][1:]):
    for column, a, b in zip(header[2:], map(float, ra[2:]), map(float, rb[2:])):
        if math.isnan(a) and math.isnan(b):
            continue
        key = (ra[1], "vs PF" if column.startswith("rmse_ref") else "vs truth")
        worst[key] = max(worst.get(key, 0.0), abs(a - b) / max(abs(a), abs(b), 1e-300))
for part in ("vs truth", "vs PF"):
    print("largest relative difference cuda vs serial, %s columns:" % part,
          {k[0]: float("%.2g" % v) for k, v in worst.items() if k[1] == part})
PY
  done
fi

if want control; then
  for run in "control --model clark-linear --controllers NONE@state,LQR@state,LQR@KF,LQR@MOM,LQR@MOM-SPEC,LQR@PF --cost D=5" \
             "control-quintic --model clark-quintic --controllers LQR-NOM@KF-NOM,LQR-NOM@MOM-NOM,LQR-NOM@PF --set bound_w=0.3 --set x0_mean=2 --set prior_mean=2"; do
  set -- $run
  name=$1; shift
  log "$name: cuda against serial"
  args=(control "$@" --members 2000 --particles 1024 --T 100 --quiet --no-plots)
  KUSHNER_BACKEND=cuda "$build/kushner" "${args[@]}" --out "$out/$name-cuda" > "$out/$name-cuda.log" 2>&1 || status=1
  KUSHNER_BACKEND=serial "$build/kushner" "${args[@]}" --out "$out/$name-serial" > "$out/$name-serial.log" 2>&1 ||
    status=1
  python3 - "$out/$name-cuda/summary.json" "$out/$name-serial/summary.json" <<'PY' | tee -a "$out/steps.log"
import json, sys
g, h = (json.load(open(p))["controllers"] for p in sys.argv[1:3])
for name in g:
    print("%-10s J cuda %.12g serial %.12g rel %.2g; estimation_error %.6f" % (name, g[name]["J"], h[name]["J"],
          abs(g[name]["J"] - h[name]["J"]) / abs(h[name]["J"]), g[name]["estimation_error"]))
PY
  done
fi

if want reproduce; then
  log "reproduce clark-table-2.1 at 20000 members (GPU)"
  KUSHNER_BACKEND=cuda /usr/bin/time -f "%e s wall, %M KB" "$build/kushner" reproduce clark-table-2.1 --members 20000 \
    --particles 4096 --out "$out/clark-table" --quiet --no-plots > "$out/clark-table.log" 2>&1 || status=1
  tail -25 "$out/clark-table.log"
  log "reproduce clark-table-3.1 (GPU)"
  KUSHNER_BACKEND=cuda /usr/bin/time -f "%e s wall, %M KB" "$build/kushner" reproduce clark-table-3.1 --members 20000 \
    --particles 1024 --out "$out/clark-table-3.1" --quiet --no-plots > "$out/clark-table-3.1.log" 2>&1 || status=1
  tail -25 "$out/clark-table-3.1.log"
fi
log "done (status $status)"
exit $status
