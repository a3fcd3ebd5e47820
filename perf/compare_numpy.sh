#!/usr/bin/env bash
# The particle-filter step on this CPU against the same filter in NumPy (perf/pf_numpy.py), timed in the
# same run: sine model, M = 100 members, N = 4096 particles, fp64, 10 repetitions each.
#   perf/compare_numpy.sh [build-dir]      (default build-native: Release, -march=native, vector math)
# Prints medians, spreads and the ratio; leaves the Google Benchmark JSON in <build-dir>/pf_cpu.json.
# Set OMP_NUM_THREADS to choose the threads (default: all cores); NumPy uses one core either way.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build-native}
if [ ! -x "$build/perf/bench_particle_filter" ]; then
  cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DKUSHNER_ENABLE_NATIVE=ON >/dev/null
  cmake --build "$build" -j"$(nproc)" --target bench_particle_filter >/dev/null
fi
python=python3
"$python" -c "import numpy" 2>/dev/null || python=/usr/bin/python3  # Debian's python3-numpy
reps=${KUSHNER_REPETITIONS:-10}
export OMP_PROC_BIND=${OMP_PROC_BIND:-false}
"$build/perf/bench_particle_filter" --benchmark_filter='members:100/particles:4096/(per_thread:0/resample:1/steps:1/precision:0/)?manual' \
  --benchmark_repetitions="$reps" --benchmark_enable_random_interleaving=true \
  --benchmark_out="$build/pf_cpu.json" --benchmark_out_format=json >/dev/null
numpy_json=$("$python" "$here/perf/pf_numpy.py" --members 100 --particles 4096 --repetitions "$reps")
"$python" - "$build/pf_cpu.json" "$numpy_json" <<'PY'
import json, statistics, sys
runs = json.load(open(sys.argv[1]))
numpy = json.loads(sys.argv[2])
def series(prefix, counter):
    return [r[counter] for r in runs["benchmarks"]
            if r.get("run_type") == "iteration" and r["name"].startswith(prefix)]
pf = series("BM_ParticleFilterStep<SineModel>/members:100/particles:4096", "particle_steps_per_s")
copy = series("BM_StreamCopy<SineModel>/members:100/particles:4096", "GB_per_s")
gbs = series("BM_ParticleFilterStep<SineModel>/members:100/particles:4096", "GB_per_s")
med = statistics.median(pf)
print(f"kushner PF step (M=100, N=4096, sine, fp64): median {med:.3g} particle-steps/s "
      f"(n={len(pf)}, spread {min(pf):.3g}..{max(pf):.3g}); context {runs['context'].get('backend')}")
print(f"  32 bytes/particle-step: {statistics.median(gbs):.3g} GB/s; BM_StreamCopy of the same bytes "
      f"{statistics.median(copy):.3g} GB/s (floor {statistics.median(copy) / 32e-9:.3g} particle-steps/s)")
print(f"NumPy {numpy['numpy']} (1 core): median {numpy['median']:.3g} particle-steps/s "
      f"(n={len(numpy['particle_steps_per_s'])}, spread {numpy['min']:.3g}..{numpy['max']:.3g})")
print(f"kushner / NumPy = {med / numpy['median']:.3g}x")
PY
