#!/usr/bin/env bash
# The filter bank's GPU figures in two device calls (phases: build, run; issue 16 part 4):
#   build  build-cuda-bank/: CUDA + Serial, kushner and test_ensemble_moments (16 command units; one 10-minute call
#          on 16 cores, about 6 minutes on 32)
#   run    test_ensemble_moments on the GPU (the output step's moments and counts against the host's) and
#          tests/cli/test_filter_determinism.sh (Serial against CUDA); then perf/compare_bank_gpu.sh (kushner CLI vs JAX vs the copy floor, M = 1e6); the same CLI runs with 2 output
#          points instead of 200 (what an output step costs); Nsight Systems' kernel and API summaries of one run
#          where nsys is installed
#   profile time per kernel and copy of one run (T = 0.05, 1e6 members), with perf/kokkos_kernel_timer.cpp and
#          CUDA_LAUNCH_BLOCKING=1 (no profiler is installed on the GPU machine)
#   OUT=<dir> KUSHNER_PHASES="build run" perf/run_bank_gpu.sh
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=${OUT:-$here/bank-gpu-out}
mkdir -p "$out"
build=$here/build-cuda-bank
phases=" ${KUSHNER_PHASES:-build run} "
want() { [[ "$phases" == *" $1 "* ]]; }
export PATH=/usr/local/cuda/bin:$PATH OMP_PROC_BIND=false CMAKE_POLICY_VERSION_MINIMUM=3.5
status=0
log() { echo "== $(date +%T) $*" | tee -a "$out/steps.log"; }
nvidia-smi --query-gpu=name,memory.total,power.limit,clocks.max.sm,driver_version --format=csv > "$out/gpu.csv" 2>&1

if want build; then
  log "configure"
  cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DKUSHNER_ENABLE_CUDA=ON -DKUSHNER_ENABLE_OPENMP=OFF \
    -DKUSHNER_ENABLE_SERIAL=ON -DKUSHNER_ENABLE_MPI=OFF -DKUSHNER_COMMAND_UNITS=16 > "$out/configure.log" 2>&1 ||
    { tail -20 "$out/configure.log"; exit 1; }
  cmake --build "$build" -j"$(nproc)" --target kushner test_ensemble_moments > "$out/build.log" 2>&1 || status=1
  grep -h -B2 -A10 -m3 " error" "$out/build.log" | head -40
  log "built (status $status)"
fi

if want run; then
  log "test_ensemble_moments (CUDA, Serial)"
  "$build/tests/test_ensemble_moments" > "$out/test_ensemble_moments.log" 2>&1 || status=1
  grep -E "^\[  (PASSED|FAILED)|FAILED \]" "$out/test_ensemble_moments.log" | tee -a "$out/steps.log"
  log "tests/cli/test_filter_determinism.sh (Serial vs CUDA)"
  bash "$here/tests/cli/test_filter_determinism.sh" "$build/kushner" > "$out/test_filter_determinism.log" 2>&1 ||
    status=1
  tail -3 "$out/test_filter_determinism.log" | tee -a "$out/steps.log"
  log "compare_bank_gpu.sh"
  KUSHNER_REPETITIONS=${KUSHNER_REPETITIONS:-3} bash "$here/perf/compare_bank_gpu.sh" "$build" 2>&1 |
    tee "$out/compare_bank_gpu.log" || status=1
  log "2 output points instead of 200 (T = 0.25 and 0.05, step loop)"
  for T in 0.25 0.05; do
    KUSHNER_BACKEND=cuda "$build/kushner" filter --model sine --filters EKF,SOF,QLF,KBL --members 1000000 --T "$T" \
      --output-points 2 --out "$out/sparse-$T" --quiet > /dev/null 2>&1 || status=1
  done
  python3 - "$out" <<'PY' | tee -a "$out/steps.log"
import json, sys
s = {T: json.load(open("%s/sparse-%s/summary.json" % (sys.argv[1], T)))["timing"]["step_loop_s"] for T in ("0.25", "0.05")}
print("2 output points: step loop %.3g member-steps/s (%.3g ms per step)" %
      (1e6 * 200 / (s["0.25"] - s["0.05"]), 1e3 * (s["0.25"] - s["0.05"]) / 200))
PY
  nsys_bin=$(command -v nsys || ls /usr/local/cuda/bin/nsys /opt/nvidia/nsight-systems/*/bin/nsys 2> /dev/null | head -1)
  if [ -n "$nsys_bin" ]; then
    log "nsys profile (T = 0.05, 200 output points over 50 steps)"
    KUSHNER_BACKEND=cuda "$nsys_bin" profile -o "$out/bank" --force-overwrite true "$build/kushner" filter --model sine \
      --filters EKF,SOF,QLF,KBL --members 1000000 --T 0.05 --out "$out/nsys-run" --quiet > "$out/nsys.log" 2>&1 || status=1
    "$nsys_bin" stats --report cuda_gpu_kern_sum --report cuda_api_sum --format csv --output "$out/bank" \
      "$out/bank.nsys-rep" >> "$out/nsys.log" 2>&1 || status=1
    rm -f "$out/bank.nsys-rep" "$out/bank.sqlite"
  else
    log "no nsys on this machine: no kernel summary"
  fi
fi
if want profile; then
  log "kernel timer (CUDA_LAUNCH_BLOCKING=1, T = 0.05: 50 steps, every one an output step)"
  g++ -O2 -shared -fPIC "$here/perf/kokkos_kernel_timer.cpp" -o "$build/kernel_timer.so" || status=1
  CUDA_LAUNCH_BLOCKING=1 KOKKOS_PROFILE_LIBRARY="$build/kernel_timer.so" KUSHNER_BACKEND=cuda "$build/kushner" filter \
    --model sine --filters EKF,SOF,QLF,KBL --members 1000000 --T 0.05 --out "$out/profile-run" --quiet \
    2> "$out/kernel_times.txt" > /dev/null || status=1
  grep -v "View::initialization" "$out/kernel_times.txt" | tee -a "$out/steps.log"
fi
log "done (status $status)"
exit $status
