#!/usr/bin/env bash
# The device call behind perf/particle_filter.md (H100, 2026-11-22): CUDA binaries built on another machine in
# build-cuda/ (with lib/libcudart.so.13 beside them), run from a copy of the repository carried to the device.
#   PF_VARIANTS="bench_particle_filter ..." PF_PHASES="test compare profile" OUT=<dir> perf/run_prebuilt_device.sh
# Variants: benchmark binaries in build-cuda/perf, run at M = 1000, N = 65536 (3 repetitions); then
# perf/run_gpu_benchmarks.sh with PF_PHASES; results tarred into $OUT/all.tgz (the device tool returns few files).
set -u
cd "$(dirname "$0")/.."
export LD_LIBRARY_PATH=$PWD/lib:${LD_LIBRARY_PATH:-}
final=$OUT; O=/tmp/o; mkdir -p $O
date -u +%T
for b in ${PF_VARIANTS:-}; do
  timeout 120 build-cuda/perf/$b --benchmark_filter="BM_ParticleFilterStep.*members:1000/particles:65536/per_thread:(0|8|16)/" \
    --benchmark_repetitions=3 --benchmark_min_time=0.3 --benchmark_out="$O/$b.json" --benchmark_out_format=json > "$O/$b.log" 2>&1
  echo "$b rc $?"; grep "median" "$O/$b.log" | grep -o "^BM[^ ]*\|particle_steps_per_s=[^ ]*" | paste - - 
done
date -u +%T
KUSHNER_PHASES="${PF_PHASES:-test compare}" OUT="$O" bash perf/run_gpu_benchmarks.sh > $O/run_gpu_benchmarks.out 2>&1
echo "run_gpu_benchmarks rc $?"
cat $O/steps.log
grep -h "Duration\|Issue Slots Busy\|Registers Per\|Achieved Occupancy\|DRAM Throughput\|Executed Instructions  \|FP64 instructions\|cuda_parallel_launch" $O/ncu_*.log 2>/dev/null | cut -c1-150
cuobjdump --list-elf build-cuda/perf/bench_particle_filter 2>&1 | head -4
cat $O/summary.txt
tar czf $final/all.tgz -C $O . ; cp $O/summary.txt $final/ 2>/dev/null
date -u +%T
