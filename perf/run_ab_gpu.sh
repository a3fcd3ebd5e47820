#!/usr/bin/env bash
# Two source trees side by side on the GPU machine: this working tree ("new") and a baseline ("old"), e.g. an
# earlier commit extracted with
#   git archive <rev> | (mkdir -p .baseline && tar -x -C .baseline)      (git-ignored; name it in `carry`)
# Builds both for CUDA, checks that the particle filter gives the same bits (tests/particle_filter_dump.cpp on
# the CUDA backend, and Basin's car), runs the new tree's particle-filter tests, then times the particle-filter
# benchmark at M = 1000, N = 65536 in alternating rounds (old, new, new with Kokkos' team_reduce, ...) in the
# same call, and prints each variant's median rate and its ratio to the old one.
#   AB_PHASES="build check bench" OUT=<dir> perf/run_ab_gpu.sh .baseline
# Environment: KUSHNER_JOBS (16), KUSHNER_CUDA_ARCH (AMPERE80), AB_ROUNDS (4), AB_REPETITIONS (3 per round),
# KUSHNER_CMAKE_ARGS (added to both configures: e.g. -DKUSHNER_SHARED_INSTANCES=OFF, which builds only what the
# targets use), AB_NEW_TARGETS (the new tree's targets; default below).
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
old_src=$(cd "${1:?usage: run_ab_gpu.sh <baseline source tree>}" && pwd)
out=${OUT:-$here/ab-out}
mkdir -p "$out"
jobs=${KUSHNER_JOBS:-16}
arch=${KUSHNER_CUDA_ARCH:-AMPERE80}
rounds=${AB_ROUNDS:-4}
reps=${AB_REPETITIONS:-3}
phases=" ${AB_PHASES:-build check bench} "
want() { [[ "$phases" == *" $1 "* ]]; }
status=0
log() { echo "== $(date +%T) $*" | tee -a "$out/steps.log"; }
export PATH=/usr/local/cuda/bin:$PATH

new_build=$here/build-cuda-ab-new
old_build=$here/build-cuda-ab-old
[ -e "$old_src/.deps" ] || ln -s "$here/.deps" "$old_src/.deps"
nvidia-smi --query-gpu=name,memory.total,power.limit,clocks.max.sm,driver_version --format=csv > "$out/gpu.csv" 2>&1

# One build per tree. With ninja (the GPU machine's image has it) all targets go to one `cmake --build` call: one
# dependency graph, each target a large nvcc translation unit (minutes, on one core) built side by side. Without
# it, CMake's makefiles build the targets of one call one after another (.NOTPARALLEL in the top Makefile), so the
# libraries are built first and then every target in its own make at once; those makes each check the shared
# libraries' dependencies, and of 7 targets started so on an H200 three failed while each built alone afterwards.
build_tree() {  # build_tree SRC BUILD TARGETS...
  local src=$1 dir=$2; shift 2
  local name generator=() libraries=(kushner_engine kushner_test_main kushner_bench_main)
  name=$(basename "$dir")
  command -v ninja >/dev/null && generator=(-G Ninja)
  cmake "${generator[@]}" -C "$here/perf/gpu_machine.cmake" -S "$src" -B "$dir" \
    -DCMAKE_BUILD_TYPE=Release -DKUSHNER_ENABLE_CUDA=ON -DKUSHNER_ENABLE_OPENMP=OFF \
    -DKUSHNER_CUDA_ARCH="$arch" ${KUSHNER_CMAKE_ARGS:-} > "$out/configure_$name.log" 2>&1 || return 1
  if [ ${#generator[@]} -gt 0 ]; then
    cmake --build "$dir" -j"$jobs" --target "${libraries[@]}" "$@" > "$out/build_$name.log" 2>&1
    return
  fi
  cmake --build "$dir" -j"$jobs" --target "${libraries[@]}" > "$out/build_$name.log" 2>&1 || return 1
  local pids=() t rc=0
  for t in "$@"; do
    cmake --build "$dir" -j2 --target "$t" > "$out/build_${name}_$t.log" 2>&1 &
    pids+=($!)
  done
  for t in "${pids[@]}"; do wait "$t" || rc=1; done
  return $rc
}

if want build; then
  log "build old ($old_src) and new, at once"
  build_tree "$old_src" "$old_build" particle_filter_dump bench_particle_filter &
  old_pid=$!
  # shellcheck disable=SC2086
  build_tree "$here" "$new_build" ${AB_NEW_TARGETS:-particle_filter_dump bench_particle_filter \
    bench_particle_filter_kokkos_team_sum test_particle_filter test_resampling test_particle_filter_references} ||
    { status=1; echo "new build failed"; }
  wait $old_pid || { status=1; echo "old build failed"; }
  grep -h -B2 -A8 "error" "$out"/build_*.log | head -60
  log "built"
fi

if want check; then
  for which in old new; do
    dir=${which}_build
    KUSHNER_BACKEND=cuda "${!dir}/tests/particle_filter_dump" > "$out/dump_$which.txt" 2>&1
    KUSHNER_BACKEND=cuda "${!dir}/tests/particle_filter_dump" car > "$out/dump_car_$which.txt" 2>&1
  done
  for f in dump dump_car; do
    if cmp "$out/${f}_old.txt" "$out/${f}_new.txt" && [ -s "$out/${f}_new.txt" ]; then
      echo "ok: $f identical on CUDA, old and new ($(wc -l < "$out/${f}_new.txt") lines)" | tee -a "$out/steps.log"
    else
      echo "FAIL: $f differs between old and new on CUDA" | tee -a "$out/steps.log"; status=1
    fi
  done
  for t in test_particle_filter test_resampling test_particle_filter_references; do
    log "$t"
    "$new_build/tests/$t" > "$out/$t.log" 2>&1 || status=1
    tail -n 3 "$out/$t.log" | tee -a "$out/steps.log"
  done
fi

if want bench; then
  filter='BM_ParticleFilterStep.*/members:1000/particles:65536/per_thread:0/resample:1/steps:[12]/|BM_StreamCopy.*/members:1000/particles:65536/'
  variants="old:$old_build/perf/bench_particle_filter new:$new_build/perf/bench_particle_filter"
  [ -x "$new_build/perf/bench_particle_filter_kokkos_team_sum" ] &&
    variants="$variants kokkos_team_sum:$new_build/perf/bench_particle_filter_kokkos_team_sum"
  for r in $(seq 1 "$rounds"); do
    for v in $variants; do
      log "round $r ${v%%:*}"
      "${v#*:}" --benchmark_filter="$filter" --benchmark_repetitions="$reps" --benchmark_report_aggregates_only=false \
        --benchmark_out="$out/bench_${v%%:*}_$r.json" --benchmark_out_format=json > "$out/bench_${v%%:*}_$r.log" 2>&1 ||
        status=1
    done
  done
  python3 - "$out" <<'PY' | tee "$out/ab_summary.txt"
import glob, json, os, statistics, sys
out = sys.argv[1]
rates = {}  # (variant, benchmark) -> [rate per repetition]
for path in glob.glob(os.path.join(out, "bench_*_*.json")):
    variant = os.path.basename(path)[len("bench_"):].rsplit("_", 1)[0]
    try:
        benchmarks = json.load(open(path))["benchmarks"]
    except (ValueError, KeyError):
        print(f"{path}: no results")
        continue
    for b in benchmarks:
        if b.get("run_type") != "iteration":
            continue
        name = b["run_name"] if "run_name" in b else b["name"]
        rate = b.get("particle_steps_per_s")
        if rate:
            rates.setdefault((variant, name), []).append(rate)
names = sorted({n for _, n in rates})
variants = [v for v in ("old", "new", "kokkos_team_sum") if any(k[0] == v for k in rates)]
print("median over all rounds (particle-steps/s; BM_StreamCopy: particles copied per s, the memory floor); ratio to old")
for n in names:
    base = statistics.median(rates.get(("old", n), [float("nan")]))
    cells = []
    for v in variants:
        r = rates.get((v, n))
        if r:
            m = statistics.median(r)
            cells.append(f"{v} {m:.4g} (n={len(r)}, {min(r):.4g}..{max(r):.4g}, x{m / base:.4f})")
    print(n + ": " + "; ".join(cells))
PY
fi
exit $status
