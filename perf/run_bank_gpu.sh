#!/usr/bin/env bash
# The filter bank's GPU figures in two device calls (phases: build, run; issue 16 part 4):
#   build  build-cuda-bank/: CUDA + Serial, kushner and test_ensemble_moments (perf/gpu_machine.cmake: sm_90 only,
#          a unit per model: 374 s on 32 cores from nothing; before it, three calls on 32 cores (570, 560, 520 s) did
#          not finish it; the build resumes where the last call stopped)
#          The run phase after it takes more than the rest of a 10-minute call (test_filter_determinism.sh alone
#          190 s): give each phase a call of its own, back to back while the machine stays warm.
#          KUSHNER_BANK_GPU_ONLY=1: the commands for the GPU alone (-DKUSHNER_GPU_BACKEND_ONLY=ON, Ninja, tests and
#          benchmarks off): kushner from nothing in 369 s of 16 cores, one call; the run phase's two checks then
#          cannot run (test_ensemble_moments not built, no serial backend to hold CUDA against), its figures can.
#   segments  a light build of its own (build-cuda-segments/: test_filter_bank_segments, test_ensemble_moments and
#          bench_filter_bank, the models' shared instances off: only what they use is compiled; on 16 cores 4.3 minutes
#          for the first two built one after another), test_filter_bank_segments on the GPU (segments in teams against a step at a time) and
#          test_ensemble_moments, then BM_FilterBankOutputSteps (a step at a time) against BM_FilterBankSegments (16
#          steps per launch, with and without watched members), M = 1e6, in one binary, KUSHNER_SEGMENT_ROUNDS (3)
#          rounds of 3, with the largest power draw and the SM clock while they ran
#   run    test_ensemble_moments on the GPU (the output step's moments and counts against the host's) and
#          tests/cli/test_filter_determinism.sh (Serial against CUDA); then perf/compare_bank_gpu.sh (kushner CLI vs JAX vs the copy floor, M = 1e6); the same CLI runs with 2 output
#          points instead of 200 (what an output step costs); Nsight Systems' kernel and API summaries of one run
#          where nsys is installed
#   profile time per kernel and copy of one run (T = 0.05, 1e6 members), with perf/kokkos_kernel_timer.cpp and
#          CUDA_LAUNCH_BLOCKING=1 (no profiler is installed on the GPU machine)
#   OUT=<dir> KUSHNER_PHASES="build run" perf/run_bank_gpu.sh
#   ab     this tree against a baseline tree (KUSHNER_BANK_BASELINE, e.g. .baseline below, given this tree's
#          perf/bench_filter_bank.cpp), both built light (bench_filter_bank, and test_ensemble_moments and
#          test_filter_bank_segments for this tree, or the tests KUSHNER_AB_TESTS names; the models' shared instances
#          off: a few minutes for both at once on 32 cores, 3 minutes on 16): the tests, then the benchmarks
#          KUSHNER_AB_BENCHMARKS picks (a regex; default BM_FilterBankOutputSteps: M = 1e6, every step an output step,
#          and no output) in alternating rounds, and the kernel timer of one run of each
# A baseline on the same machine: another source tree (e.g. `git archive <rev>` extracted into the git-ignored
# .baseline/, named in `carry`) built into its own directory, then its phases run as the new tree's:
#   KUSHNER_BANK_SOURCE=.baseline KUSHNER_BANK_BUILD=build-cuda-bank-old KUSHNER_PHASES=build perf/run_bank_gpu.sh
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=${OUT:-$here/bank-gpu-out}
mkdir -p "$out"
source_tree=$(cd "${KUSHNER_BANK_SOURCE:-$here}" && pwd)
build=$here/${KUSHNER_BANK_BUILD:-build-cuda-bank}
[ -e "$source_tree/.deps" ] || ln -s "$here/.deps" "$source_tree/.deps"
phases=" ${KUSHNER_PHASES:-build run} "
want() { [[ "$phases" == *" $1 "* ]]; }
export PATH=/usr/local/cuda/bin:$PATH OMP_PROC_BIND=false CMAKE_POLICY_VERSION_MINIMUM=3.5
status=0
log() { echo "== $(date +%T) $*" | tee -a "$out/steps.log"; }
nvidia-smi --query-gpu=name,memory.total,power.limit,clocks.max.sm,driver_version --format=csv > "$out/gpu.csv" 2>&1

if want build; then
  log "configure"
  targets=(kushner test_ensemble_moments)
  gpu_only=()
  if [ -n "${KUSHNER_BANK_GPU_ONLY:-}" ]; then
    ninja=$(command -v ninja || ls /opt/torch/.venv/bin/ninja 2> /dev/null | head -1)
    gpu_only=(-DKUSHNER_GPU_BACKEND_ONLY=ON -DKUSHNER_ENABLE_TESTS=OFF -DKUSHNER_ENABLE_BENCHMARKS=OFF)
    [ -n "$ninja" ] && gpu_only+=(-G Ninja -DCMAKE_MAKE_PROGRAM="$ninja")
    targets=(kushner)
  fi
  cmake "${gpu_only[@]}" -C "$here/perf/gpu_machine.cmake" -S "$source_tree" -B "$build" \
    -DCMAKE_BUILD_TYPE=Release -DKUSHNER_ENABLE_CUDA=ON -DKUSHNER_ENABLE_OPENMP=OFF \
    -DKUSHNER_ENABLE_SERIAL=ON -DKUSHNER_ENABLE_MPI=OFF > "$out/configure.log" 2>&1 ||
    { tail -20 "$out/configure.log"; exit 1; }
  cmake --build "$build" -j"$(nproc)" --target "${targets[@]}" > "$out/build.log" 2>&1 || status=1
  grep -h -B2 -A10 -m3 " error" "$out/build.log" | head -40
  log "built (status $status)"
fi

if want segments; then
  # (This session's full build above took more than 9 minutes of 16 cores before these two targets were linked: every
  # model's shared banks come first.)
  segments_build=$here/${KUSHNER_SEGMENTS_BUILD:-build-cuda-segments}
  log "segments: light build"
  cmake -C "$here/perf/gpu_machine.cmake" -S "$source_tree" -B "$segments_build" \
    -DCMAKE_BUILD_TYPE=Release -DKUSHNER_ENABLE_CUDA=ON \
    -DKUSHNER_ENABLE_OPENMP=OFF -DKUSHNER_ENABLE_SERIAL=ON -DKUSHNER_ENABLE_MPI=OFF -DKUSHNER_SHARED_INSTANCES=OFF \
    > "$out/configure_segments.log" 2>&1 || { tail -20 "$out/configure_segments.log"; exit 1; }
  # The libraries first: targets built side by side race on their archives. Then the three programs side by side,
  # one cmake each: given to one cmake, they were built one after another (CMake's top-level Makefile is
  # .NOTPARALLEL), each one large translation unit on one of the 16 cores.
  {
    cmake --build "$segments_build" -j"$(nproc)" --target kokkoscore kokkoscontainers kushner_engine kushner_models \
      kushner_test_main kushner_bench_main || status=1
    pids=()
    for target in test_filter_bank_segments test_ensemble_moments bench_filter_bank; do
      cmake --build "$segments_build" -j"$(nproc)" --target "$target" &
      pids+=($!)
    done
    for pid in "${pids[@]}"; do wait "$pid" || status=1; done
  } > "$out/build_segments.log" 2>&1
  grep -h -B2 -A10 -m3 " error" "$out/build_segments.log" | head -40
  log "test_filter_bank_segments (CUDA: the team form against a step at a time; Serial: the host forms)"
  "$segments_build/tests/test_filter_bank_segments" > "$out/test_filter_bank_segments.log" 2>&1 || status=1
  grep -E "^\[  (PASSED|FAILED|SKIPPED)|FAILED \]|SKIPPED \]" "$out/test_filter_bank_segments.log" | tee -a "$out/steps.log"
  log "test_ensemble_moments (CUDA: the merge of a segment's rows, a warp per column, against the host's; Serial)"
  "$segments_build/tests/test_ensemble_moments" > "$out/test_ensemble_moments.log" 2>&1 || status=1
  grep -E "^\[  (PASSED|FAILED)|FAILED \]" "$out/test_ensemble_moments.log" | tee -a "$out/steps.log"
  log "BM_FilterBankOutputSteps vs BM_FilterBankSegments, M = 1e6"
  nvidia-smi --query-gpu=power.draw,clocks.sm --format=csv,noheader,nounits -lms 200 > "$out/segments_power.csv" \
    2> /dev/null < /dev/null &
  sampler=$!
  for round in $(seq "${KUSHNER_SEGMENT_ROUNDS:-3}"); do
    "$segments_build/perf/bench_filter_bank" --benchmark_filter='BM_FilterBank(OutputSteps|Segments).*members:1000000' \
      --benchmark_repetitions=3 --benchmark_out="$out/segments-$round.json" > /dev/null 2>&1 || status=1
  done
  kill "$sampler" 2> /dev/null || true
  sort -t, -k1 -g "$out/segments_power.csv" | tail -1 | sed 's/^/largest power draw (W), SM clock (MHz): /' |
    tee -a "$out/steps.log"
  python3 - "$out" <<'PY' | tee -a "$out/steps.log"
import collections, glob, json, statistics, sys
rates = collections.defaultdict(list)
for path in sorted(glob.glob(sys.argv[1] + "/segments-*.json")):
    for b in json.load(open(path))["benchmarks"]:
        if b.get("run_type") == "iteration" and "member_steps_per_s" in b:
            rates[b["run_name"]].append(b["member_steps_per_s"])
for name in sorted(rates):
    print("%s: %.3g member-steps/s (median of %d: %s)" %
          (name, statistics.median(rates[name]), len(rates[name]), " ".join("%.3g" % r for r in rates[name])))
PY
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
if want ab; then
  old_tree=$(cd "${KUSHNER_BANK_BASELINE:?ab: KUSHNER_BANK_BASELINE names the baseline tree}" && pwd)
  [ -e "$old_tree/.deps" ] || ln -s "$here/.deps" "$old_tree/.deps"
  cp "$here/perf/bench_filter_bank.cpp" "$old_tree/perf/bench_filter_bank.cpp"
  # Ninja where there is one (the GPU machine's image has it, not on the PATH): one dependency graph per tree, its
  # targets side by side; CMake's makefiles build the targets of one call one after another.
  ninja=$(command -v ninja || ls /opt/torch/.venv/bin/ninja 2> /dev/null | head -1)
  generator=()
  [ -n "$ninja" ] && generator=(-G Ninja -DCMAKE_MAKE_PROGRAM="$ninja")
  light() {  # light SRC BUILD TARGETS...
    local src=$1 dir=$2; shift 2
    cmake "${generator[@]}" -C "$here/perf/gpu_machine.cmake" -S "$src" -B "$dir" \
      -DCMAKE_BUILD_TYPE=Release -DKUSHNER_ENABLE_CUDA=ON -DKUSHNER_ENABLE_OPENMP=OFF \
      -DKUSHNER_ENABLE_SERIAL=ON -DKUSHNER_ENABLE_MPI=OFF -DKUSHNER_SHARED_INSTANCES=OFF > "$out/configure_$(basename "$dir").log" 2>&1 &&
      cmake --build "$dir" -j16 --target "$@" > "$out/build_$(basename "$dir").log" 2>&1
  }
  log "ab: build $old_tree and this tree (light)"
  light "$old_tree" "$here/build-cuda-ab-old" bench_filter_bank &
  old_pid=$!
  ab_tests=(${KUSHNER_AB_TESTS:-test_ensemble_moments test_filter_bank_segments})
  light "$here" "$here/build-cuda-ab-new" bench_filter_bank "${ab_tests[@]}" || { status=1; echo "new build failed"; }
  wait $old_pid || { status=1; echo "old build failed"; }
  grep -h -B2 -A10 -m3 " error" "$out"/build_build-cuda-ab-*.log | head -40
  log "ab: built"
  for test in "${ab_tests[@]}"; do
    log "ab: $test"
    "$here/build-cuda-ab-new/tests/$test" > "$out/ab_$test.log" 2>&1 || status=1
    grep -E "^\[  (PASSED|FAILED|SKIPPED)|FAILED \]|SKIPPED \]" "$out/ab_$test.log" | tee -a "$out/steps.log"
  done
  for round in 1 2 3; do
    for which in old new; do
      log "ab: round $round, $which"
      "$here/build-cuda-ab-$which/perf/bench_filter_bank" \
        --benchmark_filter="${KUSHNER_AB_BENCHMARKS:-BM_FilterBankOutputSteps}" \
        --benchmark_repetitions=3 --benchmark_out="$out/ab-$which-$round.json" > /dev/null 2>&1 || status=1
    done
  done
  python3 - "$out" <<'PY' | tee -a "$out/steps.log"
import collections, glob, json, statistics, sys
rates = collections.defaultdict(list)
for path in sorted(glob.glob(sys.argv[1] + "/ab-*-*.json")):
    which = path.split("/")[-1].split("-")[1]
    for b in json.load(open(path))["benchmarks"]:
        if b.get("run_type") == "iteration" and "member_steps_per_s" in b:
            rates[(b["run_name"], which)].append(b["member_steps_per_s"])
for name in sorted({n for n, _ in rates}):
    old, new = statistics.median(rates[(name, "old")]), statistics.median(rates[(name, "new")])
    print("%s: old %.3g, new %.3g member-steps/s (medians of %d, %d): new / old %.3f" %
          (name, old, new, len(rates[(name, "old")]), len(rates[(name, "new")]), new / old))
PY
  g++ -O2 -shared -fPIC "$here/perf/kokkos_kernel_timer.cpp" -o "$out/kernel_timer.so" || status=1
  for which in old new; do
    log "ab: kernel timer, $which (CUDA_LAUNCH_BLOCKING=1, every step an output step)"
    CUDA_LAUNCH_BLOCKING=1 KOKKOS_PROFILE_LIBRARY="$out/kernel_timer.so" \
      "$here/build-cuda-ab-$which/perf/bench_filter_bank" --benchmark_filter='BM_FilterBankOutputSteps.*output:1' \
      2> "$out/ab_kernel_times_$which.txt" > /dev/null || status=1
    grep -v "View::initialization" "$out/ab_kernel_times_$which.txt" | tee -a "$out/steps.log"
  done
  rm -f "$out/kernel_timer.so"
fi
log "done (status $status)"
exit $status
