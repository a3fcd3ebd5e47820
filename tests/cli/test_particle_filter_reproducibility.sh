#!/usr/bin/env bash
# Same seed, same bits: the particle filter's per-member outputs (tests/particle_filter_dump.cpp) are
# byte-identical on 1 and 2 OpenMP threads and on the Serial backend.
set -euo pipefail
dump=$1
source "$(dirname "$0")/lib.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
OMP_NUM_THREADS=1 KUSHNER_BACKEND=openmp "$dump" > "$work/omp1"
OMP_NUM_THREADS=2 KUSHNER_BACKEND=openmp "$dump" > "$work/omp2"
KUSHNER_BACKEND=serial "$dump" > "$work/serial"
[ "$(wc -l < "$work/omp1")" -eq 41 ] || fail "expected 41 member lines, got $(wc -l < "$work/omp1")"
cmp "$work/omp1" "$work/omp2" || fail "particle filter differs between 1 and 2 OpenMP threads"
cmp "$work/omp1" "$work/serial" || fail "particle filter differs between OpenMP and Serial"
echo "ok: particle filter identical on omp1, omp2, serial ($(wc -l < "$work/omp1") members)"
