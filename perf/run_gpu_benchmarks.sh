#!/usr/bin/env bash
# The particle filter on the GPU machine: builds the CUDA configuration, runs the particle-filter tests
# (device vs host to 1e-12, systematic indices on every backend, the statistical references) and the
# benchmarks, with the PyTorch version (perf/pf_torch.py, eager and torch.compile) and the JAX one (perf/pf_jax.py,
# fp64 and fp32) timed in the same run, and `kushner filter --filters PF` through the command line (fp64, mixed,
# fp32).
# Needs: the repository with .deps (Kokkos source, googletest, benchmark, header-only libraries), CUDA,
# CMake, Python with PyTorch. No network.
#   OUT=<dir> perf/run_gpu_benchmarks.sh        (results in $OUT; default ./gpu-out)
# Environment: KUSHNER_JOBS (16), KUSHNER_CUDA_ARCH (AMPERE80: PTX JIT-compiled for Hopper),
# KUSHNER_REPETITIONS (10), KUSHNER_PHASES (default "build test compare sizes"):
#   build    configure and build build-cuda/ (kept between calls on the device machine)
#   test     the particle-filter test binaries (device vs host, systematic indices, statistical references)
#   compare  M = 1000, N = 65536: kushner's PF step (fp64, mixed and fp32, step and step_pair) and BM_StreamCopy
#            (with power draw and SM clock sampled), then PyTorch eager and torch.compile, JAX fp64 and fp32, and the
#            command line `kushner filter --model sine --filters PF` (fp64, mixed, fp32; each with --step-pairs auto
#            and never; summary.json's step-loop rate), in the same call (the side-by-side ratios)
#   sizes    every size M.N = 4e5 .. 1e9 (5 repetitions) and Kokkos vs Thrust resampling
#   profile  Nsight Compute (ncu, where installed) on one launch of each step kernel at M = 1000, N = 65536:
#            duration, throughput, occupancy, issue-slot use (ncu locks the clocks to base: durations are
#            longer than in the benchmark)
# The phases other than build only need build-cuda/ (or KUSHNER_BUILD_DIR): binaries built elsewhere (same CUDA
# major version) run; perf/run_prebuilt_device.sh does that.
# Where one call has a time limit, run the phases in separate calls, e.g.
#   KUSHNER_PHASES=build ...; KUSHNER_PHASES=test ...; KUSHNER_PHASES=compare ...; KUSHNER_PHASES=sizes ...
# Roughly: build 3-5 min at -j16, test 2-3 min, compare 3-4 min (torch.compile compiles first), sizes 3 min.
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=${OUT:-$here/gpu-out}
mkdir -p "$out"
jobs=${KUSHNER_JOBS:-16}
arch=${KUSHNER_CUDA_ARCH:-AMPERE80}
reps=${KUSHNER_REPETITIONS:-10}
build=${KUSHNER_BUILD_DIR:-$here/build-cuda}
phases=" ${KUSHNER_PHASES:-build test compare sizes} "
want() { [[ "$phases" == *" $1 "* ]]; }
status=0
step() { echo "== $(date +%T) $*" | tee -a "$out/steps.log"; }
run() {  # run NAME CMD...: output to $out/NAME.log, failure recorded, never fatal
  local name=$1; shift
  step "$name"
  local t0=$SECONDS
  "$@" > "$out/$name.log" 2>&1
  local rc=$?
  echo "   $name: exit $rc, $((SECONDS - t0)) s" | tee -a "$out/steps.log"
  [ $rc -eq 0 ] || status=1
  return $rc
}

nvidia-smi --query-gpu=name,memory.total,clocks.max.sm,clocks.max.mem,driver_version --format=csv > "$out/gpu.csv" 2>&1
git -C "$here" describe --always --dirty --abbrev=12 > "$out/git.txt" 2>&1

if want build; then
run configure cmake -C "$here/perf/gpu_machine.cmake" -S "$here" -B "$build" \
  -DCMAKE_BUILD_TYPE=Release -DKUSHNER_ENABLE_CUDA=ON \
  -DKUSHNER_ENABLE_OPENMP=OFF -DKUSHNER_ENABLE_THRUST=ON -DKUSHNER_CUDA_ARCH="$arch" || { echo "configure failed"; exit 1; }
run build cmake --build "$build" -j"$jobs" --target test_resampling test_particle_filter \
  test_particle_filter_references test_grid_filter test_particle_snapshot test_particle_random test_filter_consistency \
  bench_particle_filter bench_resampling kushner ||
  { tail -50 "$out/build.log"; exit 1; }
fi

if want test; then
  for t in test_particle_random test_resampling test_particle_filter test_particle_filter_references test_grid_filter \
    test_particle_snapshot test_filter_consistency; do
    run "$t" "$build/tests/$t" --gtest_output=json:"$out/$t.json"
  done
fi

if want compare; then
  # Power draw, SM clock and throttle reasons every 100 ms during the kushner runs: at this size the H100 runs
  # at its power limit, with the clock below its maximum (perf/particle_filter.md).
  nvidia-smi --query-gpu=power.draw,power.limit,clocks.sm,clocks.max.sm,clocks_throttle_reasons.active \
    --format=csv,noheader,nounits -lms 100 > "$out/power.csv" 2>/dev/null &
  probe=$!
  run bench_compare "$build/perf/bench_particle_filter" --benchmark_filter='members:1000/particles:65536/' \
    --benchmark_repetitions="$reps" --benchmark_enable_random_interleaving=true \
    --benchmark_out="$out/bench_compare.json" --benchmark_out_format=json
  kill $probe 2>/dev/null
  run torch_eager python3 "$here/perf/pf_torch.py" --mode eager --members 1000 --particles 65536 --repetitions "$reps"
  run torch_compile python3 "$here/perf/pf_torch.py" --mode compile --members 1000 --particles 65536 --repetitions "$reps"
  tail -n 1 "$out/torch_eager.log" > "$out/torch_eager.json" 2>/dev/null
  tail -n 1 "$out/torch_compile.log" > "$out/torch_compile.json" 2>/dev/null
  for dtype in float64 float32; do
    run "jax_$dtype" python3 "$here/perf/pf_jax.py" --dtype "$dtype" --members 1000 --particles 65536 --repetitions "$reps"
    tail -n 1 "$out/jax_$dtype.log" > "$out/jax_$dtype.json" 2>/dev/null
  done
  # The command line: 1000 steps (dt 1e-3), the default 200 output points, no progress bar; summary.json's
  # timing.particle_steps_per_s is the step loop's rate (start-up and writing excluded).
  # Each precision with step pairs (the default: the fused pass, the bank scoring one step behind) and without.
  for precision in fp64 mixed fp32; do
    for pairs in auto never; do
      name=cli_$precision; [ "$pairs" = auto ] || name=cli_${precision}_single
      rm -rf "$out/$name"
      run "$name" "$build/kushner" filter --model sine --filters PF --members 1000 --particles 65536 \
        --T 1 --dt 1e-3 --precision "$precision" --step-pairs "$pairs" --quiet --out "$out/$name"
      cp "$out/$name/summary.json" "$out/$name.json" 2>/dev/null
      rm -rf "$out/$name"
    done
  done
fi
if want sizes; then
  run bench_particle_filter "$build/perf/bench_particle_filter" --benchmark_repetitions=5 \
    --benchmark_out="$out/bench_particle_filter.json" --benchmark_out_format=json
  run bench_resampling "$build/perf/bench_resampling" --benchmark_repetitions=5 \
    --benchmark_out="$out/bench_resampling.json" --benchmark_out_format=json
fi

if want profile; then
  if command -v ncu > /dev/null; then
    filter='--benchmark_filter=BM_ParticleFilterStep.*members:1000/particles:65536/per_thread:0/resample:1/steps:1/'
    run ncu_team_step ncu --kernel-name-base mangled --kernel-name regex:ParticleTeamStep --launch-skip 250 \
      --launch-count 1 --section SpeedOfLight --section ComputeWorkloadAnalysis --section Occupancy \
      --section LaunchStats --section WarpStateStats --section InstructionStats \
      "$build/perf/bench_particle_filter" "$filter" --benchmark_repetitions=1 --benchmark_min_time=0.01
    run ncu_posterior_resample ncu --kernel-name-base mangled --kernel-name regex:'ParticlePosterior|Chunked|ParticleResampleStep' \
      --launch-skip 600 --launch-count 8 --section SpeedOfLight \
      "$build/perf/bench_particle_filter" "$filter" --benchmark_repetitions=1 --benchmark_min_time=0.01
  else
    step "profile: no ncu on this machine"
  fi
fi

python3 "$here/perf/gpu_summary.py" "$out" | tee "$out/summary.txt"
exit $status
