#!/usr/bin/env bash
# Everything the GPU machine has to show, in phases that each fit one device call (<= 10 minutes):
#   build     configure and build build-cuda/ (CUDA + OpenMP + Serial backends, Thrust), every target
#   test      the whole ctest suite (the CLI tests then also compare the cuda backend with serial)
#   bench     truth step and whole filter bank at M = 1e6 (member-steps/s), with the stream-copy floor
#   compare   `kushner compare` on the sine model (two seeds) and the cubic oscillator: M = 1e4, N = 4096,
#             T = 10, dt = 1e-3 (the tables of the filter-bank and compare issues)
#   pf        perf/run_gpu_benchmarks.sh's phases (PF_PHASES, default "compare sizes"): the particle-filter
#             step at M = 1000, N = 65536 beside PyTorch eager and torch.compile in the same call, then every size
# Results: $OUT/results.tgz (every log, JSON and summary) and $OUT/steps.log. A phase that needs the build runs
# the build first when build-cuda/ is missing (a fresh device machine). KUSHNER_DEADLINE (seconds, default 570):
# no step runs past it, so the results are packed before the device call's limit.
#   OUT=<dir> KUSHNER_PHASES="build test" perf/run_gpu_validation.sh
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=${OUT:-$here/gpu-out}
mkdir -p "$out"
work=$(mktemp -d)  # collected here, packed into $out at the end (the device tool returns few files)
build=$here/build-cuda
phases=" ${KUSHNER_PHASES:-build test bench compare} "
want() { [[ "$phases" == *" $1 "* ]]; }
export PATH=/usr/local/cuda/bin:$PATH CMAKE_POLICY_VERSION_MINIMUM=3.5 OMP_PROC_BIND=false
status=0
deadline=${KUSHNER_DEADLINE:-570}
step() {  # step NAME CMD...: output to NAME.log, time and exit code to steps.log
  local name=$1; shift
  local t0=$SECONDS left=$((deadline - SECONDS))
  [ $left -gt 5 ] || { echo "$name: skipped (deadline)" | tee -a "$work/steps.log"; status=1; return 1; }
  timeout $left "$@" > "$work/$name.log" 2>&1
  local rc=$?
  echo "$name: exit $rc, $((SECONDS - t0)) s" | tee -a "$work/steps.log"
  [ $rc -eq 0 ] || status=1
  return $rc
}
pack() { cp "$work/steps.log" "$out/" 2>/dev/null; tar -czf "$out/results.tgz" -C "$work" .; }
trap pack EXIT
trap 'exit 1' TERM INT
nvidia-smi --query-gpu=name,memory.total,clocks.max.sm,driver_version --format=csv,noheader > "$work/gpu.txt" 2>&1
git -C "$here" describe --always --dirty --abbrev=12 > "$work/git.txt" 2>&1
cat "$work/gpu.txt"

if ! want build && [ ! -x "$build/kushner" ]; then phases="$phases build "; fi
if want build; then
  step configure cmake -C "$here/perf/gpu_machine.cmake" -S "$here" -B "$build" \
    -DCMAKE_BUILD_TYPE=Release -DKUSHNER_ENABLE_CUDA=ON \
    -DKUSHNER_ENABLE_OPENMP=ON -DKUSHNER_ENABLE_THRUST=ON || { cat "$work/configure.log"; exit 1; }
  step build cmake --build "$build" -j16 || { grep -B2 -A12 -m3 "error" "$work/build.log"; exit 1; }
fi
if want test; then
  # 8 tests at a time on 16 cores: each host (OpenMP) part gets 2 threads unless the test sets its own count
  OMP_NUM_THREADS=2 step ctest ctest --test-dir "$build" -j8 --output-on-failure --timeout 400
  grep -E "tests passed|Failed|\*\*\*|Total Test" "$work/ctest.log"
fi
if want bench; then
  for b in bench_simulate_truth bench_filter_bank; do
    KUSHNER_BACKEND=cuda step "$b" "$build/perf/$b" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
    grep -E "median|Copy" "$work/$b.log"
  done
fi
if want compare; then
  common=(--members 10000 --particles 4096 --T 10 --dt 1e-3 --no-plots --quiet)
  for run in "sine 1" "sine 2" "cubic-oscillator 1"; do
    set -- $run
    KUSHNER_BACKEND=cuda step "compare-$1-seed$2" "$build/kushner" compare --model "$1" --seed "$2" "${common[@]}" \
      --out "$work/compare-$1-seed$2"
    cat "$work/compare-$1-seed$2.log"
  done
fi
if want pf; then
  OUT="$work/pf" KUSHNER_PHASES="${PF_PHASES:-compare sizes}" KUSHNER_REPETITIONS="${KUSHNER_REPETITIONS:-10}" \
    step pf bash "$here/perf/run_gpu_benchmarks.sh"
  cat "$work/pf/summary.txt" 2>/dev/null
fi
exit $status
