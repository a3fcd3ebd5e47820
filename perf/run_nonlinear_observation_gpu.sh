#!/usr/bin/env bash
# Issue 18's figures on the GPU: every filter's rmse_ref with its standard error on the nonlinear-observation
# models at M = 10^4 members, N = 16384 particles, in one device call: build the kushner target for CUDA
# (Kokkos_ARCH_AMPERE80, as perf/run_gpu_validation.sh), then `kushner compare` (no plots: the figures are drawn
# from the outputs afterwards with drivers/plots/compare_plots.py) on
#   cubic-sensor  T = 5, dt = 1e-2
#   pendulum      T = 5, dt = 2e-3 (Euler-Maruyama's energy gain: models/pendulum_model.hpp)
# Outputs under $OUT/<model>/ (summary.json, timeseries.csv, trajectories.csv, density.csv) and $OUT/steps.log.
#   OUT=<dir> perf/run_nonlinear_observation_gpu.sh
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=${OUT:-$here/gpu-out}
mkdir -p "$out"
build=${KUSHNER_BUILD_DIR:-$here/build-cuda}
export PATH=/usr/local/cuda/bin:$PATH CMAKE_POLICY_VERSION_MINIMUM=3.5 OMP_PROC_BIND=false
deadline=${KUSHNER_DEADLINE:-570}
step() {  # step NAME CMD...: output to NAME.log, time and exit code to steps.log
  local name=$1; shift
  local t0=$SECONDS left=$((deadline - SECONDS))
  [ $left -gt 5 ] || { echo "$name: skipped (deadline)" | tee -a "$out/steps.log"; return 1; }
  timeout $left "$@" > "$out/$name.log" 2>&1
  local rc=$?
  echo "$name: exit $rc, $((SECONDS - t0)) s" | tee -a "$out/steps.log"
  return $rc
}
nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader | tee "$out/gpu.txt"
git -C "$here" describe --always --dirty --abbrev=12 > "$out/git.txt" 2>&1
if [ ! -x "$build/kushner" ]; then
  step configure cmake -C "$here/perf/gpu_machine.cmake" -S "$here" -B "$build" \
    -DCMAKE_BUILD_TYPE=Release -DKUSHNER_ENABLE_CUDA=ON \
    -DKUSHNER_ENABLE_OPENMP=ON -DKUSHNER_ENABLE_THRUST=ON -DKUSHNER_ENABLE_TESTS=OFF \
    -DKUSHNER_ENABLE_BENCHMARKS=OFF || { tail -30 "$out/configure.log"; exit 1; }
fi
step build cmake --build "$build" -j16 --target kushner || { grep -B2 -A12 -m3 "error" "$out/build.log"; exit 1; }
common=(--filters all --members 10000 --particles 16384 --seed 1 --no-plots --quiet)
KUSHNER_BACKEND=cuda step cubic-sensor "$build/kushner" compare --model cubic-sensor --T 5 --dt 1e-2 \
  "${common[@]}" --out "$out/cubic-sensor"
KUSHNER_BACKEND=cuda step pendulum "$build/kushner" compare --model pendulum --T 5 --dt 2e-3 \
  "${common[@]}" --out "$out/pendulum"
rm -f "$out"/*/trajectories.csv.tmp
exit 0
