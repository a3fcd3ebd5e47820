#!/usr/bin/env bash
# The control issue's GPU figures in one or two device calls (phases: build, run):
#   build  build-cuda-control/: CUDA + OpenMP, the kushner executable, bench_control and test_closed_loop
#   run    bench_control on the GPU and on 2 OpenMP threads (car, 4 controllers, M up to 1e6); `kushner control`
#          on the GPU against Serial on the host (every controller's J to 1e-9 relative); test_closed_loop
#   OUT=<dir> KUSHNER_PHASES="build run" perf/run_control_gpu.sh
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=${OUT:-$here/control-gpu-out}
mkdir -p "$out"
build=$here/build-cuda-control
phases=" ${KUSHNER_PHASES:-build run} "
want() { [[ "$phases" == *" $1 "* ]]; }
export PATH=/usr/local/cuda/bin:$PATH OMP_PROC_BIND=false
status=0
log() { echo "== $(date +%T) $*" | tee -a "$out/steps.log"; }
nvidia-smi --query-gpu=name,memory.total,power.limit,clocks.max.sm,driver_version --format=csv > "$out/gpu.csv" 2>&1

if want build; then
  log "configure"
  cmake -C "$here/perf/gpu_machine.cmake" -S "$here" -B "$build" \
    -DCMAKE_BUILD_TYPE=Release -DKUSHNER_ENABLE_CUDA=ON -DKUSHNER_ENABLE_OPENMP=ON \
    > "$out/configure.log" 2>&1 || { tail -20 "$out/configure.log"; exit 1; }
  log "common libraries"
  cmake --build "$build" -j16 --target kushner_test_main kushner_bench_main kushner_driver > "$out/build_common.log" 2>&1 ||
    { grep -B2 -A10 -m3 "error" "$out/build_common.log"; exit 1; }
  pids=()
  for t in kushner bench_control test_closed_loop; do
    cmake --build "$build" -j4 --target "$t" > "$out/build_$t.log" 2>&1 &
    pids+=($!)
  done
  for p in "${pids[@]}"; do wait "$p" || status=1; done
  grep -h -B2 -A10 -m3 " error" "$out"/build_*.log | head -40
  log "built (status $status)"
fi

if want run; then
  log "bench_control"
  OMP_NUM_THREADS=2 "$build/perf/bench_control" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
    --benchmark_out="$out/bench_control.json" > "$out/bench_control.log" 2>&1 || status=1
  grep -E "median|Run on" "$out/bench_control.log"
  log "control: cuda against serial"
  args=(control --model sine --members 2000 --T 2 --dt 1e-2 --particles 512 --no-plots --quiet
        --controllers NONE@state,LQR@state,HJB@state,LQR@EKF,LQR@PF,HJB@PF,ASRE@ASRE --cost Q=1 --cost F=1)
  KUSHNER_BACKEND=cuda "$build/kushner" "${args[@]}" --out "$out/control_cuda" > "$out/control_cuda.log" 2>&1 || status=1
  KUSHNER_BACKEND=serial "$build/kushner" "${args[@]}" --out "$out/control_serial" > "$out/control_serial.log" 2>&1 ||
    status=1
  python3 - "$out/control_cuda/summary.json" "$out/control_serial/summary.json" <<'PY' | tee -a "$out/steps.log" || status=1
import json, sys
g, h = (json.load(open(p)) for p in sys.argv[1:3])
worst = 0.0
for name, c in g["controllers"].items():
    d = abs(c["J"] - h["controllers"][name]["J"]) / abs(h["controllers"][name]["J"])
    worst = max(worst, d)
    print(f"{name:12s} J cuda {c['J']:.12g} serial {h['controllers'][name]['J']:.12g} rel {d:.2e}")
print("worst relative difference", worst, "device", g["backend"].get("device"))
sys.exit(0 if worst < 1e-9 else 1)
PY
  log "control on the GPU at M = 1e6 (car, 4 controllers)"
  KUSHNER_BACKEND=cuda /usr/bin/time -v "$build/kushner" control --model car --set v=17 --set l=2 --set u=0 --set q=0.1 \
    --set x0_mean=0.1,0.1 --set 'x0_cov=1e-4,0;0,1e-4' --set prior_mean=0.1,0.1 --set 'prior_cov=1e-2,0;0,1e-2' \
    --T 0.3 --dt 1e-3 --members 1000000 --controllers LQR@state,ASRE@state,LQR@EKF,POLY3@EKF \
    --cost 'F=1,0;0,0' --cost 'Q=0,0;0,0' --cost target=1,0 --reference none --no-plots --out "$out/car_1e6" \
    > "$out/car_1e6.log" 2>&1 || status=1
  tail -8 "$out/car_1e6.log"
  log "test_closed_loop"
  OMP_NUM_THREADS=4 "$build/tests/test_closed_loop" > "$out/test_closed_loop.log" 2>&1 || status=1
  tail -3 "$out/test_closed_loop.log"
fi
log "done (status $status)"
exit $status
