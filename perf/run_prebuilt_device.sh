#!/usr/bin/env bash
# A device call without a build: CUDA binaries built on another machine (same CUDA major version), copied with
# perf/run_prebuilt_device.sh pack into build-cuda-bin/{perf,tests} and carried to the device, then run there:
#   perf/run_prebuilt_device.sh pack                                   (here, after building build-cuda/)
#   PF_PHASES="test compare profile" OUT=<dir> perf/run_prebuilt_device.sh   (on the device; carry build-cuda-bin)
# Runs perf/run_gpu_benchmarks.sh's phases on those binaries; every result is tarred into $OUT/all.tgz.
set -u
cd "$(dirname "$0")/.."
bin=$PWD/build-cuda-bin
if [ "${1:-}" = pack ]; then
  rm -rf "$bin" && mkdir -p "$bin/perf" "$bin/tests"
  for t in test_resampling test_particle_filter test_particle_filter_references test_particle_snapshot; do
    [ -x build-cuda/tests/$t ] && cp build-cuda/tests/$t "$bin/tests/"
  done
  for b in bench_particle_filter bench_resampling; do [ -x build-cuda/perf/$b ] && cp build-cuda/perf/$b "$bin/perf/"; done
  mkdir -p "$bin/lib" && cp -L /lib/x86_64-linux-gnu/libbenchmark.so.1debian "$bin/lib/"  # Debian's, not on the device
  du -sh "$bin"; exit 0
fi
export LD_LIBRARY_PATH=$bin/lib:/usr/local/cuda/lib64:${LD_LIBRARY_PATH:-} PATH=/usr/local/cuda/bin:$PATH
final=${OUT:?OUT: where the results go}; O=$(mktemp -d)
date -u +%T; command -v ncu nsys
KUSHNER_BUILD_DIR=$bin KUSHNER_PHASES="${PF_PHASES:-test compare}" OUT="$O" bash perf/run_gpu_benchmarks.sh > "$O/run_gpu_benchmarks.out" 2>&1
echo "run_gpu_benchmarks rc $?"
cat "$O/steps.log"
grep -h "Duration\|Issue Slots Busy\|Registers Per\|Achieved Occupancy\|DRAM Throughput\|Memory Throughput\|Compute (SM) Throughput\|FP64\|Stall\|kushner::" "$O"/ncu_*.log 2>/dev/null | cut -c1-160
cat "$O/summary.txt"
tar czf "$final/all.tgz" -C "$O" . ; cp "$O/summary.txt" "$final/" 2>/dev/null
date -u +%T
