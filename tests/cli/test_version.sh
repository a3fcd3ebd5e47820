#!/usr/bin/env bash
# `kushner --version` names kushner, Kokkos, and the backend in use with its thread count.
set -euo pipefail
kushner=$1
source "$(dirname "$0")/lib.sh"
out=$(OMP_NUM_THREADS=2 "$kushner" --version)
echo "$out"
grep -q '^kushner [0-9.]* (git ' <<<"$out" || fail "no kushner version line"
grep -q '^Kokkos [0-9]' <<<"$out" || fail "no Kokkos version line"
grep -q '^backend: openmp (2 threads)' <<<"$out" || fail "expected the OpenMP backend with 2 threads"
out=$(KUSHNER_BACKEND=serial "$kushner" --version)
grep -q '^backend: serial (1 threads)' <<<"$out" || fail "KUSHNER_BACKEND=serial not honoured"
set +e
err=$(KUSHNER_BACKEND=vulkan "$kushner" --version 2>&1 >/dev/null); rc=$?
set -e
[ $rc -eq 2 ] || fail "unknown backend: exit $rc"
[ "$err" = "kushner: error: KUSHNER_BACKEND: backend 'vulkan' is not available (built: openmp, serial)" ] || fail "message: $err"
echo ok
