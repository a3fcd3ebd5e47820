#!/usr/bin/env bash
# Same seed, same bits: the particle filter's per-member outputs (tests/particle_filter_dump.cpp) are
# byte-identical on 1 and 2 OpenMP threads and on the serial backend (one host thread); where the CUDA backend is built, equal to
# the host's to 1e-12 relative (below magnitude 1: absolute), with the same resampling counts, for these models
# and for Basin's car (no process noise, tan drift).
set -euo pipefail
dump=$1
kushner=$2  # tells which backends are built
source "$(dirname "$0")/lib.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
OMP_NUM_THREADS=1 KUSHNER_BACKEND=openmp "$dump" > "$work/omp1"
OMP_NUM_THREADS=2 KUSHNER_BACKEND=openmp "$dump" > "$work/omp2"
KUSHNER_BACKEND=serial "$dump" > "$work/serial"
[ "$(wc -l < "$work/omp1")" -eq 41 ] || fail "expected 41 member lines, got $(wc -l < "$work/omp1")"
cmp "$work/omp1" "$work/omp2" || fail "particle filter differs between 1 and 2 OpenMP threads"
cmp "$work/omp1" "$work/serial" || fail "particle filter differs between OpenMP and serial"
echo "ok: particle filter identical on omp1, omp2, serial ($(wc -l < "$work/omp1") members)"

if grep -qw cuda <<<"$(built_backends)"; then
  KUSHNER_BACKEND=cuda "$dump" > "$work/cuda"
  KUSHNER_BACKEND=serial "$dump" car > "$work/car-serial"
  KUSHNER_BACKEND=cuda "$dump" car > "$work/car-cuda"
  python3 - "$work/serial" "$work/cuda" "$work/car-serial" "$work/car-cuda" <<'PY' || fail "cuda differs from serial"
import sys
for host, device in ((sys.argv[1], sys.argv[2]), (sys.argv[3], sys.argv[4])):
    a, b = ([l.split() for l in open(p)] for p in (host, device))
    assert len(a) == len(b) and len(a) > 0, (host, len(a), len(b))
    worst = (0.0, "")
    for x, y in zip(a, b):
        assert x[:2] == y[:2] and x[-1] == y[-1], f"member {x[:2]}: resampling count {x[-1]} on the host, {y[-1]} on cuda"
        for p, q in zip(map(float.fromhex, x[2:-1]), map(float.fromhex, y[2:-1])):
            d = abs(p - q) / max(abs(p), abs(q), 1.0)
            assert d <= 1e-12, f"member {x[:2]}: {p!r} on the host, {q!r} on cuda ({d:.3g})"
            worst = max(worst, (d, x[0] + " " + x[1]))
    print(f"ok: {host.rsplit('/', 1)[-1]} vs cuda: {len(a)} members, largest difference {worst[0]:.3g} ({worst[1]})")
PY
fi
