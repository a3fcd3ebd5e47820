#!/usr/bin/env bash
# Everything the GPU machine has to show, in phases that each fit one device call (<= 10 minutes):
#   build     configure and build build-cuda/ (CUDA + OpenMP + Serial backends, Thrust), every target
#   test      the whole ctest suite (the CLI tests then also compare the cuda backend with serial)
#   bench     truth step and whole filter bank at M = 1e6 (member-steps/s), with the stream-copy floor
#   compare   `kushner compare` on the sine model (two seeds) and the cubic oscillator: M = 1e4, N = 4096,
#             T = 10, dt = 1e-3 (the tables of the filter-bank and compare issues)
# then, for the particle filter's own benchmarks and the PyTorch comparison: perf/run_gpu_benchmarks.sh
# (its phases compare and sizes reuse build-cuda/).
#   OUT=<dir> KUSHNER_PHASES="build test" perf/run_gpu_validation.sh
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=${OUT:-$here/gpu-out}
mkdir -p "$out"
build=$here/build-cuda
phases=" ${KUSHNER_PHASES:-build test bench compare} "
want() { [[ "$phases" == *" $1 "* ]]; }
export PATH=/usr/local/cuda/bin:$PATH CMAKE_POLICY_VERSION_MINIMUM=3.5
status=0
step() {  # step NAME CMD...: output to $out/NAME.log, time and exit code to steps.log
  local name=$1; shift
  local t0=$SECONDS
  "$@" > "$out/$name.log" 2>&1
  local rc=$?
  echo "$name: exit $rc, $((SECONDS - t0)) s" | tee -a "$out/steps.log"
  [ $rc -eq 0 ] || status=1
  return $rc
}
nvidia-smi --query-gpu=name,memory.total --format=csv,noheader > "$out/gpu.txt" 2>&1

if want build; then
  step configure cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DKUSHNER_ENABLE_CUDA=ON \
    -DKUSHNER_ENABLE_OPENMP=ON -DKUSHNER_ENABLE_THRUST=ON || exit 1
  step build cmake --build "$build" -j16 || { tail -40 "$out/build.log"; exit 1; }
fi
if want test; then
  (cd "$build" && step ctest ctest -j4 --output-on-failure --timeout 400)
  grep -E "tests passed|Failed|\*\*\*" "$out/ctest.log"
fi
if want bench; then
  for b in bench_simulate_truth bench_filter_bank; do
    KUSHNER_BACKEND=cuda step "$b" "$build/perf/$b" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
    grep -E "median|Copy" "$out/$b.log"
  done
fi
if want compare; then
  common=(--members 10000 --particles 4096 --T 10 --dt 1e-3 --no-plots --quiet)
  for run in "sine 1" "sine 2" "cubic-oscillator 1"; do
    set -- $run
    KUSHNER_BACKEND=cuda step "compare-$1-seed$2" "$build/kushner" compare --model "$1" --seed "$2" "${common[@]}" \
      --out "$out/compare-$1-seed$2"
  done
fi
exit $status
