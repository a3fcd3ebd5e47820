#!/usr/bin/env bash
# MPI across GPUs (issue 16 part 1), in phases that each fit one device call (<= 10 minutes):
#   build  build-cuda-mpi/: CUDA + OpenMP + MPI (OpenMPI's mpirun on the GPU machine), the kushner executable
#   run    `kushner filter --filters PF` on the sine model, N = 65536 particles, T = KUSHNER_T (default 2),
#          dt = 1e-3 (1000 T steps):
#          weak scaling  M = 1000 on 1 GPU against M = 2000 on 2 GPUs (one rank per GPU): efficiency t1 / t2
#          strong scaling M = 2000 on 1 GPU against 2 GPUs: speedup t1 / t2
#          the M = 2000 outputs of 1 and 2 ranks: every number equal to 1e-12 relative (and whether the bytes are)
#          On a machine with one GPU the two ranks share it; the summary says so.
#   segments `kushner compare --filters EKF,SOF,QLF,KBL` (no PF: the bank takes its steps in segments, the team form
#          on a GPU), M = 8000 (a last block of 64 members), members 0, 1, 2, 5000, 7999 recorded (on ranks 0, 1 and the
#          last), on 1, 2 and 3 ranks: every number of timeseries.csv, trajectories.csv and summary.json equal to
#          1e-12 relative to 1 rank's, and whether the files' bytes below their command line are the same
# KUSHNER_MPI_GPU_ONLY=1: the build for the GPU alone (no OpenMP backend; Ninja where the image has it): about 6
# minutes of 16 cores, where the build with OpenMP needs more than one call.
# Each timing is the wall time of the whole command (start-up, CUDA context, run, outputs), best of
# KUSHNER_REPETITIONS (default 2). Power and SM clock of every GPU are sampled every 500 ms while it runs.
#   OUT=<dir> KUSHNER_PHASES="build run" perf/run_mpi_gpu.sh
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=${OUT:-$here/mpi-gpu-out}
mkdir -p "$out"
build=$here/build-cuda-mpi
phases=" ${KUSHNER_PHASES:-build run} "
want() { [[ "$phases" == *" $1 "* ]]; }
export PATH=/usr/local/cuda/bin:$PATH CMAKE_POLICY_VERSION_MINIMUM=3.5 OMP_PROC_BIND=false
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
status=0
log() { echo "== $(date +%T) $*" | tee -a "$out/steps.log"; }
nvidia-smi --query-gpu=index,name,memory.total,power.limit,clocks.max.sm,driver_version --format=csv \
  > "$out/gpu.csv" 2>&1
gpus=$(nvidia-smi -L 2>/dev/null | grep -c '^GPU')
git -C "$here" describe --always --dirty --abbrev=12 > "$out/git.txt" 2>&1
mpirun --version 2>&1 | head -1 > "$out/mpirun.txt"
cat "$out/gpu.csv" "$out/mpirun.txt"

if want build; then
  log "configure"
  # perf/gpu_machine.cmake: the models' banks and commands spread over more units than the default (16-32 cores).
  backends=(-DKUSHNER_ENABLE_OPENMP=ON)
  if [ -n "${KUSHNER_MPI_GPU_ONLY:-}" ]; then
    ninja=$(command -v ninja || ls /opt/torch/.venv/bin/ninja 2> /dev/null | head -1)
    backends=(-DKUSHNER_ENABLE_OPENMP=OFF -DKUSHNER_ENABLE_SERIAL=ON -DKUSHNER_GPU_BACKEND_ONLY=ON)
    [ -n "$ninja" ] && backends+=(-G Ninja -DCMAKE_MAKE_PROGRAM="$ninja")
  fi
  cmake "${backends[@]}" -C "$here/perf/gpu_machine.cmake" -S "$here" -B "$build" \
    -DCMAKE_BUILD_TYPE=Release -DKUSHNER_ENABLE_CUDA=ON \
    -DKUSHNER_ENABLE_MPI=ON -DKUSHNER_ENABLE_TESTS=OFF -DKUSHNER_ENABLE_BENCHMARKS=OFF \
    > "$out/configure.log" 2>&1 || { tail -20 "$out/configure.log"; exit 1; }
  grep "mpi=" "$out/configure.log"
  log "build kushner"
  cmake --build "$build" -j "$(nproc)" --target kushner > "$out/build.log" 2>&1 ||
    { grep -B2 -A12 -m3 "error" "$out/build.log"; exit 1; }
  log "built"
fi

if want run; then
  [ -x "$build/kushner" ] || { echo "no $build/kushner: run the build phase first" >&2; exit 1; }
  repetitions=${KUSHNER_REPETITIONS:-2}
  T=${KUSHNER_T:-2}
  args=(filter --model sine --filters PF --particles 65536 --T "$T" --dt 1e-3 --seed 1 --output-points 20 --quiet)
  nvidia-smi --query-gpu=timestamp,index,power.draw,clocks.sm,utilization.gpu --format=csv -lms 500 \
    > "$out/power.csv" 2>/dev/null &
  sampler=$!
  # run NAME RANKS MEMBERS: best wall time of `repetitions` runs, in seconds, into $out/NAME.time
  run() {
    local name=$1 ranks=$2 members=$3 best="" t0 t1 t
    for ((i = 0; i < repetitions; ++i)); do
      rm -rf "$out/$name"
      t0=$(date +%s.%N)
      KUSHNER_BACKEND=cuda mpirun -q --bind-to none -np "$ranks" "$build/kushner" "${args[@]}" --members "$members" \
        --out "$out/$name" > "$out/$name.log" 2>&1 || { status=1; tail -3 "$out/$name.log"; }
      t1=$(date +%s.%N)
      t=$(python3 -c "print(f'{$t1 - $t0:.3f}')")
      best=$(python3 -c "print(min(x for x in [$t, ${best:-1e300}]))")
    done
    echo "$best" > "$out/$name.time"
    log "$name: $ranks rank(s), M = $members: best of $repetitions $best s ($(grep -o '"device": "[^"]*"' "$out/$name/summary.json" | head -1))"
  }
  run weak_r1_m1000 1 1000
  run weak_r2_m2000 2 2000
  run strong_r1_m2000 1 2000
  strong_r2=weak_r2_m2000  # the same run: M = 2000 on 2 ranks
  kill "$sampler" 2>/dev/null
  # Anything Kokkos or CUDA wrote besides Kokkos 3.4's note that it knows no Hopper (the sm_90 code is there).
  for f in "$out"/weak_*.log "$out"/strong_*.log; do
    grep -iv "compiled for compute capability 8.0" "$f" | grep -i "error\|warning" | sed "s|^|$(basename "$f"): |"
  done
  python3 - "$out" "$gpus" "$strong_r2" "$T" <<'PY' | tee "$out/summary.txt" || status=1
import json, os, sys
out, gpus, strong_r2 = sys.argv[1], int(sys.argv[2]), sys.argv[3]
t = lambda name: float(open(os.path.join(out, name + ".time")).read())
steps, particles = round(float(sys.argv[4]) * 1000), 65536
w1, w2, s1, s2 = t("weak_r1_m1000"), t("weak_r2_m2000"), t("strong_r1_m2000"), t(strong_r2)
where = "2 GPUs, one rank each" if gpus >= 2 else f"{gpus} GPU: the two ranks share it (no second GPU here)"
print(f"ranks on {where}; N = {particles}, {steps} steps, sine, kushner filter --filters PF, wall time of the command")
print(f"weak:   M = 1000 on 1 rank {w1:.2f} s, M = 2000 on 2 ranks {w2:.2f} s: efficiency {w1 / w2:.3f} (goal >= 0.90)")
print(f"strong: M = 2000 on 1 rank {s1:.2f} s, on 2 ranks {s2:.2f} s: speedup {s1 / s2:.3f} (goal >= 1.8)")
for name, m, secs in (("1 rank, M = 1000", 1000, w1), ("1 rank, M = 2000", 2000, s1), ("2 ranks, M = 2000", 2000, s2)):
    print(f"  {name}: {m * particles * steps / secs:.3g} particle-steps/s end to end")
# The step loop alone (summary.json's timing, rank 0's; start-up, Kokkos initialization and outputs left out).
loop = lambda name: json.load(open(os.path.join(out, name, "summary.json")))["timing"]["step_loop_s"]
l_w1, l_s1, l_s2 = loop("weak_r1_m1000"), loop("strong_r1_m2000"), loop(strong_r2)
print(f"step loop: M = 1000 on 1 rank {l_w1:.3f} s, M = 2000 on 1 rank {l_s1:.3f} s, on 2 ranks {l_s2:.3f} s: "
      f"weak efficiency {l_w1 / l_s2:.3f}, strong speedup {l_s1 / l_s2:.3f}")
print("backend R = 2:", json.dumps(json.load(open(os.path.join(out, strong_r2, "summary.json")))["backend"]))
PY
  # The M = 2000 outputs of 1 and 2 ranks: every number equal to 1e-12 relative, and whether the bytes are the same.
  same=$(python3 "$here/perf/compare_outputs.py" "$out/strong_r1_m2000" "$out/$strong_r2") || status=1
  echo "R = 1 vs R = 2 (M = 2000): $same" | tee -a "$out/summary.txt"
  python3 - "$out/power.csv" <<'PY' | tee -a "$out/summary.txt"
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))[1:]
by = {}
for r in rows:
    try:
        by.setdefault(r[1].strip(), []).append((float(r[2].split()[0]), float(r[3].split()[0]), float(r[4].split()[0])))
    except (IndexError, ValueError):
        pass
for gpu, v in sorted(by.items()):
    busy = [x for x in v if x[2] > 50] or v
    print(f"GPU {gpu}: while busy (>50% utilization, {len(busy)} samples) power {max(x[0] for x in busy):.0f} W max, "
          f"SM clock {min(x[1] for x in busy):.0f}-{max(x[1] for x in busy):.0f} MHz")
PY
fi
if want segments; then
  [ -x "$build/kushner" ] || { echo "no $build/kushner: run the build phase first" >&2; exit 1; }
  for ranks in 1 2 3; do
    rm -rf "$out/segments_r$ranks"
    KUSHNER_BACKEND=cuda mpirun -q --bind-to none --oversubscribe -np "$ranks" "$build/kushner" compare --model sine \
      --filters EKF,SOF,QLF,KBL --members 8000 --T 0.1 --seed 5 --trajectory-members 0,1,2,5000,7999 --no-plots \
      --quiet --out "$out/segments_r$ranks" > "$out/segments_r$ranks.log" 2>&1 ||
      { status=1; tail -3 "$out/segments_r$ranks.log"; }
  done
  for ranks in 2 3; do
    same=$(python3 "$here/perf/compare_outputs.py" "$out/segments_r1" "$out/segments_r$ranks" timeseries.csv \
      trajectories.csv) || status=1
    echo "segments, R = $ranks against R = 1 (M = 8000, 5 recorded members): $same" | tee -a "$out/summary.txt"
  done
fi
log "done (status $status)"
exit $status
